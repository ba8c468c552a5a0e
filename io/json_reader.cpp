#include "io/json_reader.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "core/file_checks.hpp"

namespace yarnhom::io {

json read_json_file(const std::string& path) {
  check_input_file(path);  // a FIFO would block the reader
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open");
  try {
    return json::parse(in);
  } catch (const json::parse_error& e) {
    throw std::invalid_argument(path + ": not valid JSON: " + e.what());
  }
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
