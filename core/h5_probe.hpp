#pragma once
// The probe behind core/h5.hpp's open_file: every read the readers may make, first in a child
// process.
//
// HDF5 (1.10) trusts the metadata it decodes: one corrupted byte in an object header (an
// attribute message's size, a datatype's or a dataspace's encoding, a link) can make it
// dereference a wild pointer (SIGSEGV in H5Aexists), read past the mapped file (SIGBUS),
// smash its stack (SIGABRT) or loop forever. None of that can be caught in the process, and
// no check short of decoding the format ourselves can rule it out. So before a file is handed
// to a reader, a forked child opens it and makes every kind of read the readers make, on every
// object (walking links, opening each object, looking up a missing attribute (which decodes
// every attribute message), then opening and reading each attribute as a string, a double, a
// 64-bit and a 32-bit integer, and each dataset's type, shape, filters, storage size and, up to
// kProbeReadBytes, its values). HDF5 decodes the same bytes the same way in the parent, so a
// file the child read without dying is safe to read; one that killed it (or kept it past
// kProbeSeconds) is refused, naming the object the child was at, before the parent touches it.
#include <optional>
#include <string>

namespace yarnhom::h5 {

// Empty when the child read the whole file; otherwise what killed it, with the object it was at.
struct ProbeFailure {
  std::string object, problem;
};

// Reads `path` in a forked child; nullopt when the child read it all (or no child could be
// started: the file is then read unguarded).
std::optional<ProbeFailure> probe_file(const std::string& path);

}  // namespace yarnhom::h5
