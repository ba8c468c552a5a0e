#pragma once
// The one place where baking departs from the network inside the box: the outer layer of a 1D
// table whose end slope points inward or whose end curvature is negative, so that the paper's
// quadratic continuation beyond that end rises outward with a non-decreasing slope and still
// joins the table C2 (docs/bake.md, "The safeguard outside the box").
//
// Only 1D tables. A 1D term is the energy along one strain axis with the others at 0: it must
// rise outward, and a C2 continuation inherits the table's end slope and curvature, so a
// negative one can only be removed in the table. A 2D term is a residual Psi_IJ = Psi - Psi_I -
// Psi_J (zero on the axes), which may legitimately fall outward (a Poisson coupling c s_x s_y
// along -s_y where s_x > 0): its table is the network's everywhere, and its continuation is
// first order (material/baked_eval.hpp), so it never bends the total energy down in a band.
//
// The correction. Let w be the layer width (5 % of the box's width, at least 2 knot spacings)
// and xi in [0, 1] the position across the layer (1 on the boundary). With rho1(xi) = xi^3 (xi -
// 1) and rho2(xi) = xi^3 (1 - xi)^2 / 2, both zero with their first two derivatives at xi = 0 (a
// C2 join with the untouched interior) and zero on the boundary,
//   phi(x) = alpha w rho1(xi) + beta w^2 rho2(xi)
// raises the end's outward slope by alpha and sets its curvature; alpha and beta are solved so
// that the TABLE's own one-sided slope and curvature at the end (what the quadratic inherits)
// become max(slope, 0) and max(curvature, 0) exactly. phi is added to the stored knot data
// (f, f') from its exact derivatives.
#include <string>
#include <vector>

#include "core/baked.hpp"

namespace yarnhom {

// What the repair changed at one end of a 1D table.
struct SideRepair {
  int knots = 0, repaired = 0;     // 1 for an end, and 1 when its outward slope was raised
  bool curvature_raised = false;   // the end's outward curvature was raised to 0
  double max_slope_raise = 0;      // the raise of the outward slope (physical units)
  double curvature_floor = 0;      // the floor asked for (0: none)
  bool floor_raised = false;       // the end's curvature was below that floor and now equals it
};

struct BoundaryRepair {
  std::vector<SideRepair> sides;   // 1D: lower, upper; 2D: none (never repaired)
  double layer_fraction = 0.05;    // layer width / box width
  double max_change = 0;           // largest |change| of a knot value, J/m^2
  double range = 0;                // the table's value range before the repair
  bool changed() const { return max_change > 0; }
};

// Repairs the knot data of a 1D table in place (the safeguard coefficients are NOT
// recomputed: call compute_safeguard after). A 2D table is left as it is. min_curvature
// (lower end, upper end; null: 0) raises an end's outward curvature to at least that value the
// same way (bake_model's curvature floor: where a pair's TOTAL falls outward at the box, the 1D
// curvature must turn it up within a bounded distance, bake/bake_table.hpp).
BoundaryRepair repair_boundary(BakedTable& table, const double* min_curvature = nullptr);

}  // namespace yarnhom
