#include "core/h5.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>

#include "core/file_checks.hpp"
#include "core/h5_detail.hpp"
#include "core/h5_probe.hpp"

namespace yarnhom::h5 {

using detail::Scoped;
using detail::standard_numeric_type;

namespace {

// HDF5 prints its own error stack to stderr by default; we report errors ourselves.
void silence_hdf5() {
  static bool done = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)done;
}

std::shared_ptr<hid_t> own(hid_t id, herr_t (*close)(hid_t)) {
  return std::shared_ptr<hid_t>(new hid_t(id), [close](hid_t* p) {
    close(*p);
    delete p;
  });
}

}  // namespace


Node open_file(const std::string& path) {
  silence_hdf5();
  check_input_file(path);  // a FIFO would block H5Fis_hdf5 forever
  if (H5Fis_hdf5(path.c_str()) <= 0) throw FileError(path, "", "not an HDF5 file (or truncated)");
  if (auto bad = probe_file(path)) throw FileError(path, bad->object, bad->problem);
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) throw FileError(path, "", "cannot open as HDF5 (truncated or corrupt?)");
  return Node(own(f, H5Fclose), path, "/");
}

Node create_file(const std::string& path) {
  silence_hdf5();
  // No modification times in object headers (HDF5 records them by default): the same contents
  // give the same bytes, so that runs can be compared with cmp (produce on any number of MPI
  // ranks writes the one-process file byte for byte, docs/produce.md).
  Scoped fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_obj_track_times(fcpl.get(), 0);
  hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.get(), H5P_DEFAULT);
  if (f < 0) throw FileError(path, "", "cannot create file");
  return Node(own(f, H5Fclose), path, "/");
}

Node create_file(const std::string& path, const std::string& format, int version) {
  Node root = create_file(path);
  root.set_attr("format", format);
  root.set_attr("version", version);
  return root;
}

std::string Node::child_path(const std::string& name) const {
  return path_ == "/" ? "/" + name : path_ + "/" + name;
}

void Node::fail(const std::string& object, const std::string& problem) const {
  throw FileError(file_, object, problem);
}

bool Node::has(const std::string& name) const {
  // H5Lexists needs every intermediate link to exist: walk the path.
  std::string prefix;
  size_t start = 0;
  while (start < name.size()) {
    size_t end = name.find('/', start);
    if (end == std::string::npos) end = name.size();
    prefix += (prefix.empty() ? "" : "/") + name.substr(start, end - start);
    if (H5Lexists(id(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
    start = end + 1;
  }
  return true;
}

Node Node::group(const std::string& name) const {
  if (!has(name)) fail(child_path(name), "missing group");
  {
    Scoped obj(H5Oopen(id(), name.c_str(), H5P_DEFAULT), H5Oclose);
    if (!obj.ok() || H5Iget_type(obj.get()) != H5I_GROUP) fail(child_path(name), "expected a group");
  }
  hid_t g = H5Gopen2(id(), name.c_str(), H5P_DEFAULT);
  if (g < 0) fail(child_path(name), "cannot open group");
  return Node(own(g, H5Gclose), file_, child_path(name));
}

Node Node::create_group(const std::string& name) const {
  Scoped lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  Scoped gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
  H5Pset_obj_track_times(gcpl.get(), 0);
  hid_t g = H5Gcreate2(id(), name.c_str(), lcpl.get(), gcpl.get(), H5P_DEFAULT);
  if (g < 0) fail(child_path(name), "cannot create group");
  return Node(own(g, H5Gclose), file_, child_path(name));
}

std::vector<std::string> Node::children() const {
  std::vector<std::string> names;
  H5Literate(
      id(), H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* n, const H5L_info_t*, void* out) -> herr_t {
        static_cast<std::vector<std::string>*>(out)->push_back(n);
        return 0;
      },
      &names);
  return names;
}

void Node::write_raw(const std::string& name, hid_t mem_type, hid_t file_type, const void* data,
                     size_t count, const std::vector<hsize_t>& dims) const {
  size_t n = 1;
  for (hsize_t d : dims) n *= d;
  if (n != count) fail(child_path(name), "internal error: data size does not match its shape");
  Scoped space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
  Scoped lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  Scoped dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_obj_track_times(dcpl.get(), 0);
  Scoped ds(H5Dcreate2(id(), name.c_str(), file_type, space.get(), lcpl.get(), dcpl.get(), H5P_DEFAULT), H5Dclose);
  if (!ds.ok()) fail(child_path(name), "cannot create dataset");
  if (count > 0 && H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    fail(child_path(name), "cannot write dataset");
}

void Node::write(const std::string& name, const std::vector<double>& data,
                 const std::vector<hsize_t>& dims) const {
  write_raw(name, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, data.data(), data.size(), dims);
}
void Node::write(const std::string& name, const std::vector<float>& data,
                 const std::vector<hsize_t>& dims) const {
  write_raw(name, H5T_NATIVE_FLOAT, H5T_IEEE_F32LE, data.data(), data.size(), dims);
}
void Node::write(const std::string& name, const std::vector<int>& data,
                 const std::vector<hsize_t>& dims) const {
  write_raw(name, H5T_NATIVE_INT, H5T_STD_I32LE, data.data(), data.size(), dims);
}

std::string shape_string(const std::vector<hsize_t>& dims) {
  std::string s = "[";
  for (size_t k = 0; k < dims.size(); ++k) s += (k ? ", " : "") + std::to_string(dims[k]);
  return s + "]";
}

namespace {
std::string expect_string(const std::vector<int64_t>& e) {
  std::string s = "[";
  for (size_t k = 0; k < e.size(); ++k) s += (k ? ", " : "") + (e[k] < 0 ? std::string("any") : std::to_string(e[k]));
  return s + "]";
}
}  // namespace

std::vector<hsize_t> Node::shape(const std::string& name) const {
  if (!has(name)) fail(child_path(name), "missing dataset");
  Scoped ds(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.ok()) fail(child_path(name), "not a dataset");
  Scoped space(H5Dget_space(ds.get()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0 || rank > 32) fail(child_path(name), "cannot read its shape");
  std::vector<hsize_t> dims(rank);
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

template <class T>
Array<T> Node::read_raw(const std::string& name, hid_t mem_type, const std::vector<int64_t>& expect) const {
  if (!has(name)) fail(child_path(name), "missing dataset");
  Scoped ds(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.ok()) fail(child_path(name), "not a dataset");
  Scoped type(H5Dget_type(ds.get()), H5Tclose);
  H5T_class_t cls = H5Tget_class(type.get());
  if (cls != H5T_FLOAT && cls != H5T_INTEGER) fail(child_path(name), "not a numeric dataset");
  if (!standard_numeric_type(type.get()))
    fail(child_path(name), "not a standard integer or IEEE floating-point type (corrupt type?)");
  Array<T> a;
  a.dims = shape(name);
  if (!expect.empty()) {
    bool ok = expect.size() == a.dims.size();
    for (size_t k = 0; ok && k < expect.size(); ++k) ok = expect[k] < 0 || uint64_t(expect[k]) == a.dims[k];
    if (!ok) fail(child_path(name), "wrong shape " + shape_string(a.dims) + ", expected " + expect_string(expect));
  }
  uint64_t n = 1;
  for (hsize_t d : a.dims) {
    if (d > 0 && n > kMaxElements / d)
      fail(child_path(name), "declares " + shape_string(a.dims) + " values, more than the " +
                                 std::to_string(kMaxElements) + " a dataset may hold");
    n *= d;
  }
  if (n > kMaxElements)
    fail(child_path(name), "declares " + std::to_string(n) + " values, more than the " + std::to_string(kMaxElements) +
                               " a dataset may hold");
  // Without compression filters the file must store every declared byte; fewer means a
  // truncated or corrupt file (HDF5 would return fill values for what is missing).
  {
    Scoped dcpl(H5Dget_create_plist(ds.get()), H5Pclose);
    const size_t elem = H5Tget_size(type.get());
    if (n > 0 && dcpl.ok() && H5Pget_nfilters(dcpl.get()) == 0 && elem > 0 &&
        H5Dget_storage_size(ds.get()) < n * elem)
      fail(child_path(name), "declares " + shape_string(a.dims) + " values but the file stores only " +
                                 std::to_string(H5Dget_storage_size(ds.get())) + " bytes of them (truncated or corrupt file?)");
  }
  a.data.resize(n);
  if (n > 0 && H5Dread(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.data.data()) < 0)
    fail(child_path(name), "cannot read data (truncated file?)");
  return a;
}

Array<double> Node::read_double(const std::string& name, const std::vector<int64_t>& expect) const {
  return read_raw<double>(name, H5T_NATIVE_DOUBLE, expect);
}
Array<float> Node::read_float(const std::string& name, const std::vector<int64_t>& expect) const {
  return read_raw<float>(name, H5T_NATIVE_FLOAT, expect);
}
Array<int> Node::read_int(const std::string& name, const std::vector<int64_t>& expect) const {
  return read_raw<int>(name, H5T_NATIVE_INT, expect);
}

bool Node::has_attr(const std::string& name) const {
  // Not H5Aexists: it compares `name` with every attribute message's name, and a corrupt
  // message's name is read past its end (SIGSEGV). The names come from H5Aiterate2, the same
  // walk the probe made on this file (open_file), with lengths HDF5 bounds.
  std::vector<std::string> names;
  if (H5Aiterate2(
          id(), H5_INDEX_NAME, H5_ITER_NATIVE, nullptr,
          [](hid_t, const char* n, const H5A_info_t*, void* out) -> herr_t {
            static_cast<std::vector<std::string>*>(out)->push_back(n);
            return 0;
          },
          &names) < 0)
    fail(path_, "cannot list the attributes (corrupt object header?)");
  for (const std::string& n : names)
    if (n == name) return true;
  return false;
}

namespace {
void replace_attr(hid_t loc, const std::string& name) {
  if (H5Aexists(loc, name.c_str()) > 0) H5Adelete(loc, name.c_str());
}
}  // namespace

void Node::set_attr(const std::string& name, const std::string& value) const {
  replace_attr(id(), name);
  Scoped type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), value.empty() ? 1 : value.size());
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  Scoped space(H5Screate(H5S_SCALAR), H5Sclose);
  Scoped a(H5Acreate2(id(), name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
           H5Aclose);
  const char zero = 0;
  if (!a.ok() || H5Awrite(a.get(), type.get(), value.empty() ? &zero : value.data()) < 0)
    fail(path_, "cannot write attribute '" + name + "'");
}

namespace {
void write_attr_array(const Node& n, const std::string& name, hid_t mem, hid_t file_type,
                      const void* data, hsize_t count, bool scalar) {
  replace_attr(n.id(), name);
  Scoped space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &count, nullptr), H5Sclose);
  Scoped a(H5Acreate2(n.id(), name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
           H5Aclose);
  if (!a.ok() || H5Awrite(a.get(), mem, data) < 0)
    n.fail(n.path(), "cannot write attribute '" + name + "'");
}
}  // namespace

void Node::set_attr(const std::string& name, double value) const {
  write_attr_array(*this, name, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, &value, 1, true);
}
void Node::set_attr(const std::string& name, int64_t value) const {
  write_attr_array(*this, name, H5T_NATIVE_INT64, H5T_STD_I64LE, &value, 1, true);
}
void Node::set_attr(const std::string& name, const std::vector<double>& value) const {
  write_attr_array(*this, name, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, value.data(), value.size(),
                   false);
}
void Node::set_attr(const std::string& name, const std::vector<int>& value) const {
  write_attr_array(*this, name, H5T_NATIVE_INT, H5T_STD_I32LE, value.data(), value.size(), false);
}

std::string Node::attr_string(const std::string& name) const {
  if (!has_attr(name)) fail(path_, "missing attribute '" + name + "'");
  Scoped a(H5Aopen(id(), name.c_str(), H5P_DEFAULT), H5Aclose);
  if (!a.ok()) fail(path_, "cannot open attribute '" + name + "' (corrupt file?)");
  Scoped type(H5Aget_type(a.get()), H5Tclose);
  if (!type.ok()) fail(path_, "cannot read the type of attribute '" + name + "' (corrupt file?)");
  if (H5Tget_class(type.get()) != H5T_STRING)
    fail(path_, "attribute '" + name + "' is not a string");
  {
    Scoped space(H5Aget_space(a.get()), H5Sclose);
    if (H5Sget_simple_extent_npoints(space.get()) != 1)
      fail(path_, "attribute '" + name + "' is not a single string");
  }
  std::string out;
  if (H5Tis_variable_str(type.get()) > 0) {
    // h5py writes str attributes as variable-length UTF-8: read them in their own character
    // set (HDF5 does not convert between ASCII and UTF-8).
    Scoped mem(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mem.get(), H5T_VARIABLE);
    H5Tset_cset(mem.get(), H5Tget_cset(type.get()));
    char* s = nullptr;
    if (H5Aread(a.get(), mem.get(), &s) < 0) fail(path_, "cannot read attribute '" + name + "'");
    out = s ? s : "";
    H5free_memory(s);
  } else {
    const size_t size = H5Tget_size(type.get());
    if (size == 0 || size > kMaxStringAttributeBytes)
      fail(path_, "attribute '" + name + "' declares a string of " + std::to_string(size) + " bytes, more than the " +
                      std::to_string(kMaxStringAttributeBytes) + " an attribute may hold");
    std::vector<char> buf(size + 1, 0);
    if (H5Aread(a.get(), type.get(), buf.data()) < 0)
      fail(path_, "cannot read attribute '" + name + "'");
    out = std::string(buf.data(), strnlen(buf.data(), size));
  }
  return out;
}

template <class T>
std::vector<T> Node::attr_raw(const std::string& name, hid_t mem_type) const {
  if (!has_attr(name)) fail(path_, "missing attribute '" + name + "'");
  Scoped a(H5Aopen(id(), name.c_str(), H5P_DEFAULT), H5Aclose);
  if (!a.ok()) fail(path_, "cannot open attribute '" + name + "' (corrupt file?)");
  Scoped space(H5Aget_space(a.get()), H5Sclose);
  if (!space.ok()) fail(path_, "cannot read the shape of attribute '" + name + "' (corrupt file?)");
  {
    Scoped type(H5Aget_type(a.get()), H5Tclose);
    if (!type.ok() || !standard_numeric_type(type.get()))
      fail(path_, "attribute '" + name + "' is not a number of a standard integer or IEEE floating-point type");
  }
  hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0 || uint64_t(n) > kMaxAttributeElements)
    fail(path_, "attribute '" + name + "' has " + std::to_string(n) + " entries, more than the " +
                    std::to_string(kMaxAttributeElements) + " an attribute may hold");
  std::vector<T> v(n > 0 ? n : 0);
  if (n > 0 && H5Aread(a.get(), mem_type, v.data()) < 0)
    fail(path_, "cannot read attribute '" + name + "' as a number");
  return v;
}

double Node::attr_double(const std::string& name) const {
  auto v = attr_raw<double>(name, H5T_NATIVE_DOUBLE);
  if (v.size() != 1) fail(path_, "attribute '" + name + "' is not a scalar");
  return v[0];
}
int64_t Node::attr_int(const std::string& name) const {
  auto v = attr_raw<int64_t>(name, H5T_NATIVE_INT64);
  if (v.size() != 1) fail(path_, "attribute '" + name + "' is not a scalar");
  return v[0];
}
std::vector<double> Node::attr_doubles(const std::string& name) const {
  return attr_raw<double>(name, H5T_NATIVE_DOUBLE);
}
std::vector<int> Node::attr_ints(const std::string& name) const {
  return attr_raw<int>(name, H5T_NATIVE_INT);
}

}  // namespace yarnhom::h5
