#pragma once
// Reading JSON input files (a scene, HYLC's material) with errors that name the file and the
// key: "FILE: key 'a.b': must be a number". One reader for every JSON file the program takes;
// a file's own checks extend it (sim/scene_json.cpp, material/hylc_material.cpp).
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace yarnhom::io {

using json = nlohmann::json;

// The whole file parsed; throws std::invalid_argument "FILE: cannot open" or
// "FILE: not valid JSON: ...".
json read_json_file(const std::string& path);

struct JsonReader {
  std::string file;

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;
  // j[name] of an object j; `key` is j's own key path ("" at the top).
  const json& need(const json& j, const std::string& name, const std::string& key) const;
  // j is an object whose keys are all in `allowed`.
  void only(const json& j, const std::string& where, const std::set<std::string>& allowed) const;
  double number(const json& j, const std::string& key) const;  // finite
  double nonnegative(const json& j, const std::string& key) const;
  double positive(const json& j, const std::string& key) const;
  int integer(const json& j, const std::string& key, int lo) const;         // lo .. 1e8
  int index(const json& j, const std::string& key, int lo, int hi) const;   // lo .. hi
  std::vector<double> numbers(const json& j, const std::string& key) const;
  Eigen::Vector3d vec3(const json& j, const std::string& key) const;
  // A file name, relative to the JSON file's folder unless absolute.
  std::string path(const json& j, const std::string& key) const;
};

}  // namespace yarnhom::io
