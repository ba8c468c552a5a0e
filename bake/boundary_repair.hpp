#pragma once
// The one place where baking departs from the network inside the box: a thin boundary layer
// where the network's outward slope points inward (or, in 1D, its outward curvature is
// negative), so that the safeguard beyond the box can rise outward and still join the table
// smoothly (docs/bake.md, "The safeguard outside the box").
//
// Why the table itself must change there: a continuation that is C1 with the table starts with
// the table's outward slope, so where that slope is negative no C1 continuation can be
// non-decreasing outward; in 1D, C2 also fixes the starting curvature, and a non-decreasing
// slope needs it >= 0. Where the network already satisfies both, nothing changes.
//
// The correction. Let w be the layer width (5 % of the box's width along the outward axis, at
// least 2 knot spacings) and xi in [0, 1] the position across the layer (1 on the boundary).
// With rho1(xi) = xi^3 (xi - 1) and rho2(xi) = xi^3 (1 - xi)^2 / 2, both zero with their first
// two derivatives at xi = 0 (a C2 join with the untouched interior) and zero on the boundary:
//   1D:  phi(x) = alpha w rho1(xi) + beta w^2 rho2(xi) raises the end's outward slope by alpha
//        and sets its curvature; alpha and beta are solved so that the TABLE's own one-sided
//        slope and curvature at the end (what the quadratic continuation inherits) become
//        max(slope, 0) and max(curvature, 0) exactly.
//   2D:  phi(x, y) = Delta(y) w rho1(xi) along each edge raises the outward slope by Delta(y),
//        a cubic Hermite spline through per-knot raises (delta_j, delta'_j): the boundary
//        slope's spline is made non-negative on every cell where it was not (values raised to
//        >= 0, slopes limited to |h v'| <= 3 v, a sufficient condition for a non-negative cubic
//        Hermite piece), and delta'_j = 0 at the edge's two end knots, so the corrections of
//        two edges that meet at a corner do not change each other's boundary slopes.
// phi is added to the stored knot data (f, f_x, f_y, f_xy) exactly, from its derivatives.
#include <string>
#include <vector>

#include "core/baked.hpp"

namespace yarnhom {

// What the repair changed on one side of a table (1D: an end; 2D: an edge).
struct SideRepair {
  int knots = 0, repaired = 0;     // boundary knots, and those whose outward slope was raised
  bool curvature_raised = false;   // 1D only: the end's outward curvature was raised to 0
  double max_slope_raise = 0;      // largest raise of the outward slope (physical units)
};

struct BoundaryRepair {
  std::vector<SideRepair> sides;   // 1D: lower, upper; 2D: x_lower, x_upper, y_lower, y_upper
  double layer_fraction = 0.05;    // layer width / box width
  double max_change = 0;           // largest |change| of a knot value, J/m^2
  double range = 0;                // the table's value range before the repair
  bool changed() const { return max_change > 0; }
};

// Repairs the knot data of a 1D or 2D table in place (the safeguard coefficients are NOT
// recomputed: call compute_safeguard after).
BoundaryRepair repair_boundary(BakedTable& table);

// The outward slope of a table along an edge, on each cell of the edge, is the cubic Hermite
// piece through (v0, h v0') and (v1, h v1'); its minimum on [0, 1]. Exposed for the tests.
double hermite_piece_min(double v0, double m0, double v1, double m1);

}  // namespace yarnhom
