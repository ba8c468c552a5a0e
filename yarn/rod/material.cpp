#include "yarn/rod/material.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"

namespace yarnhom::yarn {

Material parse_material(const std::string& text, const std::string& file) {
  Material m;
  std::istringstream in(text);
  std::string raw;
  int lineno = 0;
  while (std::getline(in, raw)) {
    ++lineno;
    const std::string where = "line " + std::to_string(lineno);
    std::string line = raw.substr(0, raw.find('#'));
    const auto eq = line.find('=');
    auto trim = [](std::string s) {
      const auto b = s.find_first_not_of(" \t\r");
      if (b == std::string::npos) return std::string();
      return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
    };
    if (trim(line).empty()) continue;
    if (eq == std::string::npos) throw FileError(file, where, "expected 'key = value'");
    const std::string key = trim(line.substr(0, eq)), val = trim(line.substr(eq + 1));
    if (key == "slide_constraint") {
      if (val == "true" || val == "1") m.slide_constraint = true;
      else if (val == "false" || val == "0") m.slide_constraint = false;
      else throw FileError(file, where, "slide_constraint must be true or false, got '" + val + "'");
      continue;
    }
    char* end = nullptr;
    const double v = std::strtod(val.c_str(), &end);
    if (val.empty() || *end != '\0' || !std::isfinite(v))
      throw FileError(file, where, "value of '" + key + "' is not a number: '" + val + "'");
    if (!(v > 0)) throw FileError(file, where, "'" + key + "' must be positive");
    if (key == "young") m.young = v;
    else if (key == "shear") m.shear = v;
    else if (key == "density") m.density = v;
    else if (key == "contact_stiffness") m.contact_stiffness = v;
    else
      throw FileError(file, where, "unknown key '" + key +
                                       "' (known: young, shear, density, contact_stiffness, slide_constraint)");
  }
  return m;
}

Material read_material(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw FileError(path, "", "cannot open for reading");
  std::stringstream ss;
  ss << f.rdbuf();
  return parse_material(ss.str(), path);
}

std::string format_material(const Material& m) {
  std::ostringstream o;
  o.precision(17);
  o << "young = " << m.young << "\nshear = " << m.shear << "\ndensity = " << m.density
    << "\ncontact_stiffness = " << m.contact_stiffness
    << "\nslide_constraint = " << (m.slide_constraint ? "true" : "false") << "\n";
  return o.str();
}

}  // namespace yarnhom::yarn

namespace yarnhom::yarn {

std::vector<std::string> builtin_material_names() { return {"hylc-calibrated", "yarnhom-2025"}; }

bool is_builtin_material(const std::string& name) {
  for (const auto& n : builtin_material_names())
    if (n == name) return true;
  return false;
}

Material builtin_material(const std::string& name) {
  if (name == "hylc-calibrated") return Material{};
  if (name == "yarnhom-2025") {
    Material m;
    m.young = 1.0e6;
    m.shear = 1.0e6 / 3.0;
    m.density = 1.2e3;
    m.contact_stiffness = 1.0e6;
    return m;
  }
  std::string names;
  for (const auto& n : builtin_material_names()) names += (names.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown material '" + name + "' (built-in: " + names + ")");
}

Material load_material(const std::string& what) {
  if (std::filesystem::exists(what)) return read_material(what);
  if (is_builtin_material(what)) return builtin_material(what);
  std::string names;
  for (const auto& n : builtin_material_names()) names += (names.empty() ? "" : ", ") + n;
  throw std::invalid_argument("material '" + what + "' is neither a file nor a built-in material (" + names + ")");
}

}  // namespace yarnhom::yarn
