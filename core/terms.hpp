#pragma once
// The 14 energy terms of the additive model (spec section 3):
//   Psi(s) = Psi0 + sum_{I in {0,1,2,3,5}} Psi_I(s_I) + sum_{(I,J) in P} Psi_IJ(s_I, s_J).
// Index 4 (II_a) has no term of its own: bending enters through principal curvatures.
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace yarnhom {

// Strain components of the HYLC 6-vector (spec section 2).
inline constexpr int kStrainDim = 6;
inline constexpr std::array<const char*, kStrainDim> kStrainSymbols = {"s_x", "s_a", "s_y",
                                                                       "II_x", "II_a", "II_y"};

struct Term {
  std::string name;          // "0", "02", ... as in files and on the command line
  std::vector<int> indices;  // strain indices, 1 or 2 of them
  int dim() const { return static_cast<int>(indices.size()); }
};

// All 14 terms in the spec's order: 0 1 2 3 5 01 02 03 05 12 13 15 23 25.
const std::vector<Term>& all_terms();

// The term with this name; throws std::invalid_argument naming the valid ones otherwise.
const Term& term_by_name(std::string_view name);

// Parses "0,02,15" (or "all") into terms, in catalogue order, without duplicates; an empty
// list (or one of only commas) is refused.
std::vector<Term> parse_term_list(std::string_view list);

// Where a strain component means something, for every strain the program reads (points,
// boxes): stretches s_x, s_y in (-1, 10] (a stretch ratio between 0 and 11), the shear cosine
// s_a in (-1, 1), curvatures within +-1e6 1/m (a radius of curvature of one micrometre).
// Returns "" when v is allowed, else the rule, naming the component ("s_x must lie in (-1, 10]").
std::string strain_domain_violation(int strain_index, double v);

// HYLC's default sampling box of one strain component (spec section 2), with the bending
// range k (1/m) given, since it depends on the pattern.
struct Range {
  double lower, upper;
};
Range default_range(int strain_index, double bend_x = 200.0, double bend_y = 200.0);

// The entry of `items` (a dataset's terms, a model's networks, a baked file's tables: anything
// with a .term) for the term called `name`, or null.
template <class T>
const T* find_term(const std::vector<T>& items, const std::string& name) {
  for (const T& t : items)
    if (t.term.name == name) return &t;
  return nullptr;
}

}  // namespace yarnhom
