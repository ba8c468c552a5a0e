#pragma once
// Checks on the files a command names, made before any work so that a wrong path costs
// nothing and can never destroy what it must not.
//
// Inputs must be regular files: a FIFO, a device or a socket would block a reader or feed it
// an endless stream (a FIFO named by a model's `dataset` attribute used to hang `bake`).
//
// Outputs (written by AtomicOutput under a temporary name beside the final one, then renamed)
// are refused when they name a folder, anything but a regular file (a device, a FIFO or a
// socket would be replaced by a regular file), the same file as one of the command's inputs
// (same device and inode: another name, a hard link or a symbolic link to it included), or a
// place where no file can be created (a missing folder, no permission, a read-only file
// system). Symbolic links are FOLLOWED: an output that is a link to a regular file is written
// to that file (the link stays a link, as with the shell's `>`); a link to a missing file is
// refused, since following it would create a file at a place the user may not expect.
#include <string>
#include <vector>

namespace yarnhom {

// Throws FileError(path, "", problem) unless path names an existing regular file (after
// following symbolic links). `what` names the option or argument in the message ("--data").
void check_input_file(const std::string& path, const std::string& what = "");

// Throws FileError naming path and `option` for an output that must not be written (see
// above). Inputs that are empty or do not exist are ignored. Returns the file that will be
// written: path, or the file it links to.
std::string check_output_file(const std::string& path, const std::vector<std::string>& inputs,
                              const std::string& option = "-o");

// An output folder (the -o of sim, strip, accuracy, study, pipeline, plot): refused when it
// exists and is not a folder (a file, a FIFO, a device), or no file can be created in it, or
// when it does not exist and cannot be created (its nearest existing ancestor is not a folder
// or takes no new folder: /proc, a read-only file system). Both are tried by making a probe
// (removed at once), since access() says yes to root almost everywhere. Creates nothing.
// core/console.hpp's prepare_output_folder also creates it and checks the files in it.
void check_output_folder(const std::string& path, const std::string& option = "-o");

// The kind of a non-regular file for messages: "a directory", "a FIFO", "a character
// device", ...
std::string file_kind(unsigned mode);

}  // namespace yarnhom
