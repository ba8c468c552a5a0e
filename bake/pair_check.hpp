#pragma once
// What a term pair's data does at the box, for the total energy the simulator sees: in the
// plane of strains I and J (the others 0) the total is Psi_I(s_I) + Psi_J(s_J) + Psi_IJ(s_I, s_J)
// plus constants (every other residual vanishes there with its gradient). Outside the box the
// safeguard makes each 1D term a convex quadratic and each residual first order along the
// outward normal (material/baked_eval.hpp), so along every outward ray of an edge band the total's
// slope is non-decreasing by construction, starting from the total's outward slope at the box.
// Two things the continuation cannot change without changing the data, and which bake
// therefore reports per pair instead:
//   - where the total's outward slope at the box boundary is negative (the data themselves fall
//     outward in total): the energy falls on leaving the box there before the 1D curvature
//     turns it up;
//   - a corner whose outward twist T = sigma_x sigma_y d2Psi_IJ/ds_I ds_J is negative and larger
//     than the 1D terms' outward curvatures allow, T^2 > K_I K_J: along diagonal corner rays
//     (c, s) the total's curvature K_I c^2 + 2 T c s + K_J s^2 is negative, so its slope falls
//     there. No C1 continuation can avoid it: on the corner's borders the residual's mixed
//     derivative is the band's, T, while its curvature along the border is 0.
// K_I is the 1D term's curvature just outside the pair's box along I (the safeguard's quadratic
// when the boxes share that end, the table's curvature when the 1D box reaches farther).
#include <array>
#include <string>
#include <vector>

#include "material/baked_eval.hpp"
#include "core/baked.hpp"

namespace yarnhom {

struct PairCheck {
  std::string pair;                      // the 2D term's name
  bool has_1d[2] = {false, false};       // the 1D terms of its two strains are in the model
  // Edges in the order x_lower, x_upper, y_lower, y_upper (x: the pair's first strain).
  std::array<int, 4> points{}, falling{};  // sample points on the edge; where the total falls outward
  std::array<double, 4> worst_slope{};     // most negative total outward slope on the edge (0 if none)
  double slope_scale = 0;                  // largest |total outward slope| on the boundary
  // Corners in the order of kBakedCornerNames: the outward twist T and the 1D curvatures.
  std::array<double, 4> twist{}, k_first{}, k_second{};
  std::array<bool, 4> corner_bends{};      // T < 0 and T^2 > K_I K_J
  bool any() const;
  std::string summary() const;             // "" when nothing to report
};

// t2 the pair's residual; ti, tj the 1D terms of its first and second strain (null: absent, 0).
PairCheck check_pair(const BakedTerm& t2, const BakedTerm* ti, const BakedTerm* tj);

// One check per 2D table of the model, in table order (1D tables get an empty check).
std::vector<PairCheck> check_pairs(const BakedModel& m);

// The 1D term of strain `strain` among `terms` (null: the model has none).
const BakedTerm* find_one_d(const std::vector<BakedTerm>& terms, int strain);

}  // namespace yarnhom
