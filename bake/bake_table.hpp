#pragma once
// Baking (spec section 8): a term sampled on a regular knot grid over its box with exact
// derivatives, 1D (f, f') for cubic Hermite, 2D (f, f_x, f_y, f_xy) for bicubic Hermite; the
// 1D end repair where a 1D term's end slope points inward or curves down
// (bake/boundary_repair.hpp); for a whole model, the corner twist repair of a 2D table's four
// corner knots where the total would bend down beyond a corner (bake/corner_twist.hpp) and the
// edge slope repair of its boundary knots' outward derivatives where the total falls outward
// at the box (bake/edge_slope_repair.hpp; no interior 2D knot is ever changed, nor any knot
// value); the safeguard coefficients implied by those knots
// (material/baked_eval.hpp); and, per term pair, what the total energy does at the box
// (bake/pair_check.hpp).
#include <array>
#include <string>
#include <vector>

#include "bake/boundary_repair.hpp"
#include "bake/corner_twist.hpp"
#include "bake/edge_slope_repair.hpp"
#include "bake/pair_check.hpp"
#include "bake/term_function.hpp"
#include "core/baked.hpp"
#include "core/model.hpp"

namespace yarnhom {

// Knot k of n on [lo, hi]; the last knot is hi exactly.
inline double knot_position(double lo, double hi, int n, int k) {
  return k == n - 1 ? hi : lo + (hi - lo) * k / (n - 1);
}

// What baking one table had to change: the 1D end repair of the knots, where the safeguard
// departs from the paper's continuation, and (2D, from bake_model) the pair's total energy.
struct BakeReport {
  BoundaryRepair repair;
  std::array<std::string, 2> floor_pair;  // 1D: the pair whose falling total set an end's curvature floor
  CornerTwistRepair corners;  // 2D, from bake_model
  EdgeSlopeRepair edges;      // 2D, from bake_model
  SafeguardDepartures departures;
  PairCheck pair;
  // One line in words: "the paper's continuation" or where and by how much it departed.
  std::string summary(const BakedTable& table) const;
};

// Bakes any function over the box with `knots` knots per axis (>= 2). Provenance fields of the
// result are left default. repair = false keeps a 1D table's knots exactly the function's (its
// continuation then only as safe as the function's ends: for tests of interpolation); a 2D
// table's knots are the function's (only bake_model's corner twist and edge slope repairs change them).
// min_curvature: a 1D table's outward end curvature floors (lower, upper; null: 0).
BakedTable bake_function(const Term& term, const std::vector<double>& lower,
                         const std::vector<double>& upper, const std::vector<int>& knots,
                         const TermFunction& f, BakeReport* report = nullptr, bool repair = true,
                         const double* min_curvature = nullptr);

// Bakes one trained network over its box: res1d knots in 1D, res2d x res2d in 2D. Copies the
// network's provenance (normalization, architecture, epochs, backend, status).
BakedTable bake_network(const ModelNetwork& net, int res1d, int res2d, BakeReport* report = nullptr,
                        bool repair = true, const double* min_curvature = nullptr);

// Where a pair's total falls outward at an edge of its box (slope S < 0, data), the 1D term of
// that edge's strain gets an outward end curvature of at least -S / (this x its box width), so
// that beyond the box the total turns up within this fraction of the box width and is bounded
// below (the energy dips by at most |S| x that distance / 2).
inline constexpr double kSlopeRecoveryFraction = 0.5;

// Bakes every network of a model as one material, in four steps: every table; the 1D tables
// again with the curvature floors their pairs need (kSlopeRecoveryFraction, only at ends that a
// pair's box shares); the corner twists of every 2D table against the final 1D tables
// (bake/corner_twist.hpp); then its edge slopes (bake/edge_slope_repair.hpp). Beyond the box
// the total in every pair plane then never decreases along any outward ray from the boundary
// on, and is bounded below. psi0 is Psi(0) if known.
BakedModel bake_model(const Model& model, const std::string& model_path, int res1d, int res2d,
                      double psi0, bool psi0_known, std::vector<BakeReport>* reports = nullptr);

}  // namespace yarnhom
