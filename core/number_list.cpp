#include "core/number_list.hpp"

#include <cmath>
#include <stdexcept>

namespace yarnhom {

std::vector<double> parse_numbers(const std::string& text, const std::string& what) {
  std::vector<double> v;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string item = text.substr(start, end - start);
    size_t used = 0;
    double x;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      throw std::invalid_argument(what + ": '" + item + "' is not a number");
    }
    if (used != item.size()) throw std::invalid_argument(what + ": '" + item + "' is not a number");
    // NaN and infinity are never a meaningful strain, size or coordinate.
    if (!std::isfinite(x)) throw std::invalid_argument(what + ": '" + item + "' is not a finite number");
    v.push_back(x);
    start = end + 1;
  }
  return v;
}

std::vector<double> parse_stretch_range(const std::string& text) {
  const size_t a = text.find(':'), b = text.find(':', a == std::string::npos ? a : a + 1);
  if (a == std::string::npos || b == std::string::npos)
    throw std::invalid_argument("--stretch " + text + ": expected first:last:step, e.g. 1.0:1.7:0.05");
  const auto v = parse_numbers(text.substr(0, a) + "," + text.substr(a + 1, b - a - 1) + "," + text.substr(b + 1), "--stretch");
  if (!(v[2] > 0) || !(v[1] >= v[0]) || !(v[0] > 0) || !std::isfinite(v[1]))
    throw std::invalid_argument("--stretch " + text + ": need 0 < first <= last and step > 0");
  std::vector<double> out;
  for (int k = 0;; ++k) {
    const double x = v[0] + k * v[2];
    if (x > v[1] + 1e-9 * v[2]) break;
    out.push_back(x);
    if (k > 100000) throw std::invalid_argument("--stretch " + text + ": too many steps");
  }
  return out;
}

std::vector<int> parse_ints(const std::string& text, const std::string& what, int max) {
  std::vector<int> out;
  for (double x : parse_numbers(text, what)) {
    if (!(x >= 1 && x <= max) || x != std::floor(x))
      throw std::invalid_argument(what + ": expected positive integers up to " + std::to_string(max));
    out.push_back(int(x));
  }
  return out;
}

std::pair<int, int> parse_tiles(const std::string& text, const std::string& what) {
  std::vector<int> v;
  try {
    v = parse_ints(text, what, 64);
  } catch (const std::invalid_argument&) {
    v.clear();
  }
  if (v.size() != 2) throw std::invalid_argument(what + ": expected two integers NX,NY in [1, 64], got '" + text + "'");
  return {v[0], v[1]};
}

}  // namespace yarnhom
