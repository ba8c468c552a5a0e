#include "io/json_reader.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "core/file_checks.hpp"

namespace yarnhom::io {

namespace {

// nlohmann's DOM builder, told where it is: the key path of the value being read ("a.b[2]"),
// so that a number the parser refuses (1e999 overflows a double) or a syntax error names the
// key. Nesting is bounded (a hostile file of a million brackets).
class KeyedDomParser : public nlohmann::detail::json_sax_dom_parser<json> {
 public:
  using Base = nlohmann::detail::json_sax_dom_parser<json>;
  KeyedDomParser(json& root, const std::string& file) : Base(root, true), file_(file) {}

  bool null() { return begin_value() && Base::null(); }
  bool boolean(bool v) { return begin_value() && Base::boolean(v); }
  bool number_integer(number_integer_t v) { return begin_value() && Base::number_integer(v); }
  bool number_unsigned(number_unsigned_t v) { return begin_value() && Base::number_unsigned(v); }
  bool number_float(number_float_t v, const string_t& s) { return begin_value() && Base::number_float(v, s); }
  bool string(string_t& v) { return begin_value() && Base::string(v); }
  bool binary(binary_t& v) { return begin_value() && Base::binary(v); }
  bool start_object(std::size_t n) { return begin_value() && push(false) && Base::start_object(n); }
  bool start_array(std::size_t n) { return begin_value() && push(true) && Base::start_array(n); }
  bool key(string_t& k) {
    frames_.back().key = k;
    return Base::key(k);
  }
  bool end_object() {
    frames_.pop_back();
    return Base::end_object();
  }
  bool end_array() {
    frames_.pop_back();
    return Base::end_array();
  }
  template <class Exception>
  bool parse_error(std::size_t, const std::string&, const Exception& e) {
    const std::string where = path(true);
    std::string what = e.what();
    if (what.rfind("[json.exception.", 0) == 0 && what.find("] ") != std::string::npos)
      what = what.substr(what.find("] ") + 2);  // the library's own tag: not for users
    const std::string problem = e.id == 406 ? what + ": a number must be finite (at most about 1.8e308)" : "not valid JSON: " + what;
    throw std::invalid_argument(file_ + ": " + (where.empty() ? "" : "key '" + where + "': ") + problem);
  }

 private:
  struct Frame {
    bool array;
    std::string key;
    long count = 0;  // arrays: elements begun
  };
  static constexpr size_t kMaxDepth = 256;

  bool begin_value() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().count;
    return true;
  }
  bool push(bool array) {
    if (frames_.size() >= kMaxDepth)
      throw std::invalid_argument(file_ + ": key '" + path(false) + "': nested deeper than " + std::to_string(kMaxDepth) +
                                  " arrays and objects");
    frames_.push_back({array, "", 0});
    return true;
  }
  // The key path; `pending`: the innermost array's next element is the one being read.
  std::string path(bool pending) const {
    std::string p;
    for (size_t k = 0; k < frames_.size(); ++k) {
      const Frame& f = frames_[k];
      if (f.array) {
        const long i = (pending && k + 1 == frames_.size()) ? f.count : f.count - 1;
        p += "[" + std::to_string(std::max(0L, i)) + "]";
      } else if (!f.key.empty()) {
        p += (p.empty() ? "" : ".") + f.key;
      }
    }
    return p;
  }

  std::string file_;
  std::vector<Frame> frames_;
};

}  // namespace

json read_json_file(const std::string& path) {
  check_input_file(path);  // a FIFO would block the reader
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open");
  json result;
  KeyedDomParser sax(result, path);
  try {
    json::sax_parse(in, &sax);
  } catch (const json::exception& e) {  // what the DOM builder itself throws (sizes)
    throw std::invalid_argument(path + ": not valid JSON: " + e.what());
  }
  return result;
}

void JsonReader::fail(const std::string& key, const std::string& problem) const {
  throw std::invalid_argument(file + ": key '" + key + "': " + problem);
}

const json& JsonReader::need(const json& j, const std::string& name, const std::string& key) const {
  if (!j.is_object()) fail(key, "must be an object");
  if (!j.contains(name)) fail(key.empty() ? name : key + "." + name, "missing");
  return j[name];
}

void JsonReader::only(const json& j, const std::string& where, const std::set<std::string>& allowed) const {
  if (!j.is_object()) fail(where, "must be an object");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!allowed.count(it.key())) fail(where.empty() ? it.key() : where + "." + it.key(), "unknown key");
}

double JsonReader::number(const json& j, const std::string& key) const {
  if (!j.is_number()) fail(key, "must be a number");
  const double x = j.get<double>();
  if (!std::isfinite(x)) fail(key, "must be finite");
  return x;
}

double JsonReader::nonnegative(const json& j, const std::string& key) const {
  const double x = number(j, key);
  if (!(x >= 0)) fail(key, "must be >= 0");
  return x;
}

double JsonReader::positive(const json& j, const std::string& key) const {
  const double x = number(j, key);
  if (!(x > 0)) fail(key, "must be positive");
  return x;
}

int JsonReader::integer(const json& j, const std::string& key, int lo) const {
  if (!j.is_number_integer()) fail(key, "must be an integer");
  const long long x = j.get<long long>();
  if (x < lo || x > 100000000) fail(key, "must be an integer >= " + std::to_string(lo));
  return int(x);
}

int JsonReader::index(const json& j, const std::string& key, int lo, int hi) const {
  if (!j.is_number_integer()) fail(key, "must be an integer");
  const long long k = j.get<long long>();
  if (k < lo || k > hi) fail(key, "must be between " + std::to_string(lo) + " and " + std::to_string(hi));
  return int(k);
}

std::vector<double> JsonReader::numbers(const json& j, const std::string& key) const {
  if (!j.is_array()) fail(key, "must be an array of numbers");
  std::vector<double> v;
  v.reserve(j.size());
  for (const json& x : j) v.push_back(number(x, key));
  return v;
}

Eigen::Vector3d JsonReader::vec3(const json& j, const std::string& key) const {
  if (!j.is_array() || j.size() != 3) fail(key, "must be an array of 3 numbers");
  return Eigen::Vector3d(number(j[0], key), number(j[1], key), number(j[2], key));
}

std::string JsonReader::path(const json& j, const std::string& key) const {
  if (!j.is_string()) fail(key, "must be a file name (string)");
  std::filesystem::path p(j.get<std::string>());
  if (p.is_relative()) p = std::filesystem::path(file).parent_path() / p;
  return p.string();
}

}  // namespace yarnhom::io
