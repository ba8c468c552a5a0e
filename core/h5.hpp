#pragma once
// A small RAII layer over the HDF5 C API: one type, Node (a file or a group), that opens,
// creates, reads and writes what the project's formats need, and reports every failure as
// a FileError naming the file, the object and the problem.
#include <hdf5.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace yarnhom::h5 {

// An n-dimensional array read from a file, row-major.
template <class T>
struct Array {
  std::vector<T> data;
  std::vector<hsize_t> dims;
  size_t rows() const { return dims.empty() ? 1 : dims[0]; }
  size_t cols() const { return dims.size() < 2 ? 1 : dims[1]; }
};

class Node {
 public:
  // Open an existing group below this node ("a" or "a/b"); throws "missing group" otherwise.
  Node group(const std::string& name) const;
  Node create_group(const std::string& name) const;
  bool has(const std::string& name) const;  // a link of that name (group or dataset) exists
  std::vector<std::string> children() const;

  // Datasets. dims must multiply to data.size(); written row-major.
  void write(const std::string& name, const std::vector<double>& data,
             const std::vector<hsize_t>& dims) const;
  void write(const std::string& name, const std::vector<float>& data,
             const std::vector<hsize_t>& dims) const;
  void write(const std::string& name, const std::vector<int>& data,
             const std::vector<hsize_t>& dims) const;
  // Read a dataset converting to T (HDF5 converts float <-> double on read). Before any data
  // is read, the declared shape is checked: against `expect` when given (one entry per
  // dimension, -1 for "any"), against kMaxElements, and against the bytes the file actually
  // stores, so that a corrupt or hostile file that declares 2^40 values is refused at once,
  // naming the file and the dataset, instead of allocating them.
  Array<double> read_double(const std::string& name, const std::vector<int64_t>& expect = {}) const;
  Array<float> read_float(const std::string& name, const std::vector<int64_t>& expect = {}) const;
  Array<int> read_int(const std::string& name, const std::vector<int64_t>& expect = {}) const;
  // The declared shape of a dataset, without reading it.
  std::vector<hsize_t> shape(const std::string& name) const;

  // Attributes.
  bool has_attr(const std::string& name) const;
  void set_attr(const std::string& name, const std::string& value) const;
  void set_attr(const std::string& name, const char* value) const { set_attr(name, std::string(value)); }
  void set_attr(const std::string& name, double value) const;
  void set_attr(const std::string& name, int64_t value) const;
  void set_attr(const std::string& name, int value) const { set_attr(name, int64_t(value)); }
  void set_attr(const std::string& name, const std::vector<double>& value) const;
  void set_attr(const std::string& name, const std::vector<int>& value) const;
  std::string attr_string(const std::string& name) const;
  double attr_double(const std::string& name) const;
  int64_t attr_int(const std::string& name) const;
  std::vector<double> attr_doubles(const std::string& name) const;
  std::vector<int> attr_ints(const std::string& name) const;

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }  // "/" or "/terms/02"
  std::string child_path(const std::string& name) const;
  hid_t id() const { return *id_; }
  [[noreturn]] void fail(const std::string& object, const std::string& problem) const;

 private:
  friend Node open_file(const std::string&);
  friend Node create_file(const std::string&);
  Node(std::shared_ptr<hid_t> id, std::string file, std::string path)
      : id_(std::move(id)), file_(std::move(file)), path_(std::move(path)) {}
  void write_raw(const std::string& name, hid_t mem_type, hid_t file_type, const void* data,
                 size_t count, const std::vector<hsize_t>& dims) const;
  template <class T>
  Array<T> read_raw(const std::string& name, hid_t mem_type, const std::vector<int64_t>& expect) const;
  template <class T>
  std::vector<T> attr_raw(const std::string& name, hid_t mem_type) const;

  std::shared_ptr<hid_t> id_;  // closes itself (file or group) with the last copy
  std::string file_, path_;
};

// The most values one dataset may declare (2^28: 2 GiB of doubles; the project's largest, a
// 10000 x 10000 baked table, has 1e8).
inline constexpr uint64_t kMaxElements = uint64_t(1) << 28;
// The most entries one numeric attribute may have.
inline constexpr uint64_t kMaxAttributeElements = uint64_t(1) << 20;
// The longest fixed-length string attribute (1 MiB; the project's are paths and names).
inline constexpr uint64_t kMaxStringAttributeBytes = uint64_t(1) << 20;

// "[3, 4]" for messages.
std::string shape_string(const std::vector<hsize_t>& dims);

// Open for reading; refuses a missing file, one that is not a regular file (a FIFO would block
// the reader) or one that is not HDF5, naming it. Before the file is returned, a forked child
// makes every kind of read the readers make on every object (h5.cpp: the probe); a file whose
// corrupt metadata crashes or hangs the HDF5 library there is refused, naming the object,
// instead of crashing the program (HDF5 1.10 dies by SIGSEGV in H5Aexists on one flipped byte
// of an attribute message).
Node open_file(const std::string& path);
// Create (truncate) for writing.
Node create_file(const std::string& path);
// A new file stamped with its format's name and version (the root attributes `format` and
// `version` every yarnhom file carries, docs/conventions.md).
Node create_file(const std::string& path, const std::string& format, int version);

}  // namespace yarnhom::h5
