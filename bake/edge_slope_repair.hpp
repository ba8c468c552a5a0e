#pragma once
// The edge slope repair: where a pair's total energy falls outward at an edge of its box, the
// 2D table's outward normal derivative at that edge's knots is raised so that the total's
// outward slope is >= 0 on the whole edge. With it the total rises (weakly) along every outward
// ray from the box boundary itself, not only from some distance out (issue 12's safeguard
// criterion, tested literally in tests/bake/test_safeguard.cpp).
//
// In the plane of a pair (I, J) the total is Psi_I + Psi_J + Psi_IJ. Beyond an edge the
// residual Psi_IJ continues to first order and the 1D term's quadratic carries curvature
// K_I >= 0 (docs/bake.md), so along an edge ray the total's slope is S + K_I t, where
//     S = sigma (dPsi_IJ/dn + Psi_I'(X))
// is its outward slope at the boundary (sigma = +-1 the outward sign, X the bound). S < 0 is
// data: the sampled energy falls at the edge of the sampled space (buckling, jamming). No C1
// continuation can start rising from a falling boundary, so the repair changes the table
// where the data falls, inside the box, and as little as possible:
//   1. at every boundary knot with S < 0 the stored normal derivative f_n becomes -Psi_I'(X),
//      so S = 0 there (the knot's value f and its tangential derivative are kept);
//   2. between knots S is the cubic Hermite interpolant of the knots' S along the edge, whose
//      slopes are the knots' cross derivatives f_xy (times h); where it still dips below 0 in a
//      cell, the cross derivative of that cell's non-corner knots is set to 0 (the cubic is then
//      monotone between two values >= 0), and a corner knot, whose f_xy the corner twist repair
//      owns (bake/corner_twist.hpp), gets S >= |h f_xy| / 3 instead (which keeps the cubic >= 0
//      whatever the cell's other knot does with zero slope).
// A boundary knot's f_n and f_xy enter only the cells of the outermost layer along that edge:
// the table changes nowhere else, and its knot values never. `bake` prints the change. Tables
// with extrapolation "linear" (fit-splines, HYLC's convention) are not touched.
#include <array>
#include <string>

#include "material/baked_eval.hpp"
#include "core/baked.hpp"

namespace yarnhom {

struct EdgeSlopeRepair {
  std::array<int, 4> knots_raised{};     // per edge (kBakedEdgeNames order): knots whose f_n was raised
  std::array<int, 4> cross_zeroed{};     // per edge: knots whose f_xy was set to 0
  std::array<double, 4> worst_before{};  // per edge: the most negative S before (0 if none)
  double max_change = 0;                 // largest |change| of the table's value in the outer cell layer
  double max_grad_change = 0;            // largest |change| of its gradient (physical units)
  double range = 0;                      // the table's knot value range
  bool any() const {
    for (int e = 0; e < 4; ++e)
      if (knots_raised[e] || cross_zeroed[e]) return true;
    return false;
  }
  std::string summary() const;  // "" when nothing was changed
};

// Repairs the 2D table t2 in place (after the corner twist repair, against the final 1D terms)
// and recomputes its safeguard coefficients. ti, tj: the 1D terms of its first and second
// strain (null: absent, slope 0).
EdgeSlopeRepair repair_edge_slopes(BakedTable& t2, const BakedTerm* ti, const BakedTerm* tj);

}  // namespace yarnhom
