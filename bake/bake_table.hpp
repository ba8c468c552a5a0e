#pragma once
// Baking (spec section 8): a term sampled on a regular knot grid over its box with exact
// derivatives, 1D (f, f') for cubic Hermite, 2D (f, f_x, f_y, f_xy) for bicubic Hermite; the
// boundary repair where the outward slope points inward (bake/boundary_repair.hpp); and the
// safeguard coefficients implied by those knots (bake/baked_eval.hpp).
#include <string>
#include <vector>

#include "bake/boundary_repair.hpp"
#include "bake/term_function.hpp"
#include "core/baked.hpp"
#include "core/model.hpp"

namespace yarnhom {

// Knot k of n on [lo, hi]; the last knot is hi exactly.
inline double knot_position(double lo, double hi, int n, int k) {
  return k == n - 1 ? hi : lo + (hi - lo) * k / (n - 1);
}

// What baking one table had to change: the boundary repair of the knots, and where the
// safeguard departs from the paper's continuation.
struct BakeReport {
  BoundaryRepair repair;
  SafeguardDepartures departures;
  // One line in words: "the paper's continuation" or where and by how much it departed.
  std::string summary(const BakedTable& table) const;
};

// Bakes any function over the box with `knots` knots per axis (>= 2). Provenance fields of the
// result are left default. repair = false keeps the knots exactly the function's (the
// safeguard is then only as safe as the function's boundary: for tests of interpolation).
BakedTable bake_function(const Term& term, const std::vector<double>& lower,
                         const std::vector<double>& upper, const std::vector<int>& knots,
                         const TermFunction& f, BakeReport* report = nullptr, bool repair = true);

// Bakes one trained network over its box: res1d knots in 1D, res2d x res2d in 2D. Copies the
// network's provenance (normalization, architecture, epochs, backend, status).
BakedTable bake_network(const ModelNetwork& net, int res1d, int res2d, BakeReport* report = nullptr,
                        bool repair = true);

// Bakes every network of a model. psi0 is Psi(0) if known (from the dataset).
BakedModel bake_model(const Model& model, const std::string& model_path, int res1d, int res2d,
                      double psi0, bool psi0_known, std::vector<BakeReport>* reports = nullptr);

}  // namespace yarnhom
