#include "io/obj_write.hpp"

#include "core/error.hpp"

namespace yarnhom {

ObjWriter::ObjWriter(const std::string& path) : out_(path), f_(std::fopen(out_.temp_path().c_str(), "w")) {
  if (!f_) throw FileError(path, "", "cannot open for writing");
}

ObjWriter::~ObjWriter() {
  if (f_) std::fclose(f_);
}

void ObjWriter::comment(const std::string& text) { std::fprintf(f_, "# %s\n", text.c_str()); }
void ObjWriter::object(const std::string& name) { std::fprintf(f_, "o %s\n", name.c_str()); }
void ObjWriter::group(const std::string& name) { std::fprintf(f_, "g %s\n", name.c_str()); }
void ObjWriter::vertex(double x, double y, double z) { std::fprintf(f_, "v %.9g %.9g %.9g\n", x, y, z); }
void ObjWriter::texcoord(double u, double v) { std::fprintf(f_, "vt %.9g %.9g\n", u, v); }

void ObjWriter::face(std::initializer_list<long> v) {
  std::fputc('f', f_);
  for (long i : v) std::fprintf(f_, " %ld", i);
  std::fputc('\n', f_);
}

void ObjWriter::face_with_texcoords(std::initializer_list<long> v) {
  std::fputc('f', f_);
  for (long i : v) std::fprintf(f_, " %ld/%ld", i, i);
  std::fputc('\n', f_);
}

void ObjWriter::polyline(const std::vector<long>& v) {
  std::fputc('l', f_);
  for (long i : v) std::fprintf(f_, " %ld", i);
  std::fputc('\n', f_);
}

void ObjWriter::commit() {
  std::FILE* f = f_;
  f_ = nullptr;
  if (std::fclose(f) != 0) throw FileError(out_.final_path(), "", "write failed");
  out_.commit();
}

}  // namespace yarnhom
