#pragma once
// Wavefront OBJ out: the one writer behind every OBJ the program writes (the continuum
// simulator's frames, a yarn strip's centrelines, an RVE's yarns as tubes). Numbers as %.9g;
// written under a temporary name and renamed over the final path on commit(), so an
// interrupted run never leaves half a file (core/atomic_file.hpp).
#include <Eigen/Core>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"

namespace yarnhom {

class ObjWriter {
 public:
  explicit ObjWriter(const std::string& path);  // throws FileError when it cannot write
  ~ObjWriter();
  ObjWriter(const ObjWriter&) = delete;
  ObjWriter& operator=(const ObjWriter&) = delete;

  void comment(const std::string& text);                // "# text"
  void object(const std::string& name);                 // "o name"
  void group(const std::string& name);                  // "g name"
  void vertex(double x, double y, double z);            // "v x y z"
  void texcoord(double u, double v);                    // "vt u v"
  void face(std::initializer_list<long> v);             // "f a b c ..." (1-based)
  void face_with_texcoords(std::initializer_list<long> v);  // "f a/a b/b c/c" (vertex = texture index)
  void polyline(const std::vector<long>& v);            // "l a b c ..." (1-based)
  void commit();                                        // closes and renames; throws on a failed write

 private:
  AtomicOutput out_;
  std::FILE* f_ = nullptr;
};

}  // namespace yarnhom
