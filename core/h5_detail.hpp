#pragma once
// Internals shared by core/h5.cpp and core/h5_probe.cpp (not part of the h5 API).
#include <hdf5.h>

#include <memory>

namespace yarnhom::h5::detail {

// A scoped hid_t with its matching close function.
class Scoped {
 public:
  Scoped(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Scoped() {
    if (id_ >= 0) close_(id_);
  }
  Scoped(const Scoped&) = delete;
  Scoped& operator=(const Scoped&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// A numeric type HDF5 can convert safely: exactly one of the standard integer and IEEE
// types. A corrupt type message (an integer's precision or offset beyond its size, a float's
// field positions) makes HDF5's conversion read outside its buffers (SIGSEGV in
// H5T__bit_find from H5Aread), so anything else is refused before a value is read.
inline bool standard_numeric_type(hid_t type) {
  static const hid_t kStandard[] = {
      H5T_STD_I8LE,  H5T_STD_I8BE,  H5T_STD_U8LE,  H5T_STD_U8BE,  H5T_STD_I16LE, H5T_STD_I16BE,
      H5T_STD_U16LE, H5T_STD_U16BE, H5T_STD_I32LE, H5T_STD_I32BE, H5T_STD_U32LE, H5T_STD_U32BE,
      H5T_STD_I64LE, H5T_STD_I64BE, H5T_STD_U64LE, H5T_STD_U64BE, H5T_IEEE_F32LE, H5T_IEEE_F32BE,
      H5T_IEEE_F64LE, H5T_IEEE_F64BE};
  for (hid_t t : kStandard)
    if (H5Tequal(type, t) > 0) return true;
  return false;
}

}  // namespace yarnhom::h5::detail
