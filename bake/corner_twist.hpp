#pragma once
// The corner twist repair: the one change baking makes to a 2D table, at its four corner knots
// only, so that outside the box the total energy rises along every corner ray by construction.
//
// In the plane of a pair (I, J), beyond a corner of the pair's box, the total energy is the two
// 1D quadratics plus the residual's bilinear corner (docs/bake.md), so along an outward corner
// ray (c, s) >= 0 its curvature is K_I c^2 + 2 T c s + K_J s^2, with K_I, K_J the 1D terms'
// outward curvatures and T = sigma_x sigma_y d2Psi_IJ/ds_I ds_J the residual's outward twist at
// the corner. C1 with the two edge bands fixes T to the table's mixed derivative at the corner
// knot (on the corner's borders the residual's Hessian is [[0, T], [T, 0]]), so no continuation
// can help: where T < -sqrt(K_I K_J) the total bends down along diagonal rays and, since the
// bilinear term grows without bound, falls to minus infinity far out (a cloth simulation that
// reaches such a corner runs away: a stretch-bending corner of a trained stockinette reached
// -575 J/m^2 at (s_y, II_y) = (5.6, 2074 /m)).
//
// The repair raises that one knot value, f_xy at the corner knot, to the outward twist
// T' = -gamma sqrt(K_I K_J) (gamma = 0.9: the corner's worst diagonal keeps 10 % of the
// geometric-mean stiffness, so the total is a positive definite quadratic far out and bounded
// below). A bicubic Hermite knot's f_xy enters only the one cell at that corner, through
// h_x h_y H10(u) H10(v): inside the box the table changes in that cell alone, by at most
// |dT| h_x h_y (4/27)^2 in value; every other knot, and so every other cell, is the network's.
// Missing 1D terms count as K = 0 (then T' = 0). Tables with extrapolation "linear"
// (fit-splines, HYLC's convention) are not touched.
#include <array>
#include <string>

#include "material/baked_eval.hpp"
#include "core/baked.hpp"

namespace yarnhom {

inline constexpr double kCornerTwistGamma = 0.9;

struct CornerTwistRepair {
  std::array<bool, 4> repaired{};            // corners in the order of kBakedCornerNames
  std::array<double, 4> twist_before{}, twist_after{}, k_first{}, k_second{};
  double max_change = 0;                     // largest |change| of the table's value in a corner cell
  double max_grad_change = 0;                // largest |change| of its gradient (physical units)
  double range = 0;                          // the table's knot value range
  bool any() const { return repaired[0] || repaired[1] || repaired[2] || repaired[3]; }
  std::string summary() const;               // "" when nothing was changed
};

// Repairs the corner knots of the 2D table t2 in place and recomputes its safeguard
// coefficients. ti, tj: the 1D terms of its first and second strain (null: absent).
CornerTwistRepair repair_corner_twists(BakedTable& t2, const BakedTerm* ti, const BakedTerm* tj,
                                       double gamma = kCornerTwistGamma);

}  // namespace yarnhom
