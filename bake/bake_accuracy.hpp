#pragma once
// Bake accuracy (spec section 9): max and mean |baked - network| on a fine grid over the box,
// relative to the term's range (max - min of the network on that grid), and the same for the
// gradient relative to the largest gradient on the grid. The grid's points are offset from the
// knots (at any resolution up to the grid's), so that the interpolation error is seen.
#include <vector>

#include "material/baked_eval.hpp"
#include "bake/term_function.hpp"

namespace yarnhom {

struct BakeDeviation {
  double range = 0;                 // max - min of the reference on the grid, J/m^2
  double max_abs = 0, mean_abs = 0; // |baked - reference|, J/m^2
  double max_rel = 0, mean_rel = 0; // the same over range
  double grad_max_rel = 0;          // max |grad baked - grad reference| / max |grad reference|
};

// grid: points per axis (1D default 2003, 2D 203 x 203).
BakeDeviation bake_deviation(const TermFunction& reference, const TermFunction& baked, int d,
                             const std::vector<double>& lower, const std::vector<double>& upper, int grid = 0);

// Where a repair changed a 2D table: the largest |change| of its value and of its gradient
// (physical units) between `before` and `after` on the (n0 + 1) x (n1 + 1) grid of the rectangle
// [lo0, hi0] x [lo1, hi1], raised into max_value and max_gradient (left as they are if larger).
void max_table_change(const BakedTerm& before, const BakedTerm& after, const double lo[2], const double hi[2], int n0,
                      int n1, double& max_value, double& max_gradient);

}  // namespace yarnhom
