#include "core/terms.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace yarnhom {

const std::vector<Term>& all_terms() {
  static const std::vector<Term> terms = {
      {"0", {0}},      {"1", {1}},      {"2", {2}},      {"3", {3}},      {"5", {5}},
      {"01", {0, 1}},  {"02", {0, 2}},  {"03", {0, 3}},  {"05", {0, 5}},  {"12", {1, 2}},
      {"13", {1, 3}},  {"15", {1, 5}},  {"23", {2, 3}},  {"25", {2, 5}},
  };
  return terms;
}

const Term& term_by_name(std::string_view name) {
  for (const Term& t : all_terms())
    if (t.name == name) return t;
  std::string valid;
  for (const Term& t : all_terms()) valid += (valid.empty() ? "" : " ") + t.name;
  throw std::invalid_argument("unknown term '" + std::string(name) + "' (valid terms: " + valid + ")");
}

std::vector<Term> parse_term_list(std::string_view list) {
  if (list == "all") return all_terms();
  if (list.empty()) throw std::invalid_argument("empty term list (give terms such as 0,02 or 'all')");
  std::vector<bool> want(all_terms().size(), false);
  size_t start = 0;
  while (start <= list.size()) {
    size_t end = list.find(',', start);
    if (end == std::string_view::npos) end = list.size();
    std::string_view item = list.substr(start, end - start);
    if (!item.empty()) {
      const Term& t = term_by_name(item);
      want[&t - all_terms().data()] = true;
    }
    start = end + 1;
  }
  std::vector<Term> out;
  for (size_t i = 0; i < want.size(); ++i)
    if (want[i]) out.push_back(all_terms()[i]);
  if (out.empty()) throw std::invalid_argument("empty term list");
  return out;
}

std::string strain_domain_violation(int i, double v) {
  const std::string name = i >= 0 && i < kStrainDim ? kStrainSymbols[i] : "strain";
  if (!std::isfinite(v)) return name + " must be finite";
  switch (i) {
    case 0:
    case 2: return v > -1 && v <= 10 ? "" : name + " must lie in (-1, 10] (a stretch)";
    case 1: return v > -1 && v < 1 ? "" : name + " must lie in (-1, 1) (the cosine of the angle between the axes)";
    case 3:
    case 4:
    case 5: return std::abs(v) <= 1e6 ? "" : name + " must lie within +-1e6 1/m (a curvature)";
    default: return "strain index out of range 0..5";
  }
}

Range default_range(int i, double bend_x, double bend_y) {
  switch (i) {
    case 0:
    case 2: return {-0.2, 1.0};
    case 1: return {-0.7, 0.7};
    case 3: return {-bend_x, bend_x};
    case 4: return {-std::max(bend_x, bend_y), std::max(bend_x, bend_y)};
    case 5: return {-bend_y, bend_y};
    default: throw std::invalid_argument("strain index out of range 0..5");
  }
}

}  // namespace yarnhom
