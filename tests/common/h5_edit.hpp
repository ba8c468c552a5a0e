#pragma once
// Damaging an HDF5 file in place for tests, through the C API: what a corrupt, hostile or
// foreign-written (h5py) file may hold.
#include <hdf5.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace yarnhom::test::h5edit {

// An open file (read-write), closed at scope exit; HDF5's own error printing silenced.
class File {
 public:
  explicit File(const std::string& path) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    id_ = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    if (id_ < 0) throw std::runtime_error("h5edit: cannot open " + path);
  }
  ~File() {
    if (id_ >= 0) H5Fclose(id_);
  }
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  hid_t id() const { return id_; }

 private:
  hid_t id_ = -1;
};

inline bool exists(const File& f, const std::string& path) { return H5Lexists(f.id(), path.c_str(), H5P_DEFAULT) > 0; }

inline void remove(const File& f, const std::string& path) {
  if (exists(f, path)) H5Ldelete(f.id(), path.c_str(), H5P_DEFAULT);
}

inline void rename(const File& f, const std::string& from, const std::string& to) {
  H5Lmove(f.id(), from.c_str(), f.id(), to.c_str(), H5P_DEFAULT, H5P_DEFAULT);
}

// Replaces `path` by a float64 dataset of shape dims. With data: written (sizes must agree);
// without: chunked and never written, so that a file of a few kB declares any size.
inline void put_dataset(const File& f, const std::string& path, const std::vector<hsize_t>& dims,
                        const std::vector<double>* data = nullptr, hid_t type = H5T_IEEE_F64LE) {
  remove(f, path);
  hid_t space = H5Screate_simple(int(dims.size()), dims.data(), nullptr);
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (!data && !dims.empty()) {
    std::vector<hsize_t> chunk(dims.size(), 1);
    H5Pset_chunk(dcpl, int(dims.size()), chunk.data());
  }
  hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(lcpl, 1);
  hid_t ds = H5Dcreate2(f.id(), path.c_str(), type, space, lcpl, dcpl, H5P_DEFAULT);
  if (ds >= 0 && data) H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data->data());
  if (ds >= 0) H5Dclose(ds);
  H5Pclose(lcpl);
  H5Pclose(dcpl);
  H5Sclose(space);
}

inline hid_t open_object(const File& f, const std::string& obj) { return H5Oopen(f.id(), obj.c_str(), H5P_DEFAULT); }

inline void drop_attr(hid_t o, const std::string& name) {
  if (H5Aexists(o, name.c_str()) > 0) H5Adelete(o, name.c_str());
}

// Numeric attribute (scalar when one value) of the given file type.
inline void set_attr(const File& f, const std::string& obj, const std::string& name, const std::vector<double>& v,
                     hid_t type = H5T_IEEE_F64LE) {
  hid_t o = open_object(f, obj);
  drop_attr(o, name);
  const hsize_t n = v.size();
  hid_t space = n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr);
  hid_t a = H5Acreate2(o, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_DOUBLE, v.data());
  H5Aclose(a);
  H5Sclose(space);
  H5Oclose(o);
}

// A string attribute as h5py writes a Python str: variable-length, UTF-8, scalar.
inline void set_attr_vlen_utf8(const File& f, const std::string& obj, const std::string& name, const std::string& value) {
  hid_t o = open_object(f, obj);
  drop_attr(o, name);
  hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  hid_t space = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(o, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  const char* s = value.c_str();
  H5Awrite(a, type, &s);
  H5Aclose(a);
  H5Sclose(space);
  H5Tclose(type);
  H5Oclose(o);
}

// A fixed-length string attribute (h5py's numpy bytes), possibly an array of several.
inline void set_attr_fixed(const File& f, const std::string& obj, const std::string& name, const std::string& value,
                           hsize_t count = 1) {
  hid_t o = open_object(f, obj);
  drop_attr(o, name);
  hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, value.empty() ? 1 : value.size());
  hid_t space = count == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &count, nullptr);
  hid_t a = H5Acreate2(o, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  std::string buf;
  for (hsize_t i = 0; i < count; ++i) buf += value.empty() ? std::string(1, '\0') : value;
  H5Awrite(a, type, buf.data());
  H5Aclose(a);
  H5Sclose(space);
  H5Tclose(type);
  H5Oclose(o);
}

inline void remove_attr(const File& f, const std::string& obj, const std::string& name) {
  hid_t o = open_object(f, obj);
  if (o < 0) return;
  drop_attr(o, name);
  H5Oclose(o);
}

}  // namespace yarnhom::test::h5edit
