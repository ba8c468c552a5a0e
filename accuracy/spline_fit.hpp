#pragma once
// The HYLC-style baseline (Sperl et al. 2020, "Homogenized Yarn-Level Cloth"): every term of a
// dataset fitted by a Hermite spline with few knots, written as a baked table with linear
// extrapolation, so that the continuum simulator runs it exactly like a baked network.
// docs/accuracy.md says what of HYLC's fitting this reproduces and what it cannot.
//
// Representation (ARCSim-HYLC's HermiteSpline1D/2D): cubic Hermite in 1D from (f, f') per
// knot, bicubic Hermite in 2D from (f, f_x, f_y, f_xy) per knot; outside the knots the tangent
// (1D) or the tensor product of tangents (2D), core/baked.hpp "linear".
//
// Knots: n per axis, uniformly spaced with a knot at strain 0 whenever 0 lies inside the data
// (HYLC's published materials all have one), the spacing the smallest that lets the knots
// cover the data on both sides of 0.
//
// Fit: the unknowns are the knot values and slopes (slopes scaled by the spacing); the
// objective, in the units of the networks' normalization (energy / its standard deviation,
// strain / the box width), is
//   sum_i (f(s_i) - E_i)^2 + w_g |grad f(s_i) - G_i|^2 + lambda N int |D^2 f|^2
// (D^2 f the Hessian, Frobenius norm: the thin-plate energy in 2D), linear least squares.
// Constraints, as in HYLC's materials:
//   1D: f(0) = 0 (the term is defined so), and f monotone away from one knot (its minimum):
//       every cell satisfies Fritsch-Carlson's sufficient condition (0 <= f'/secant <= 3 at
//       both ends), so the outward slopes of the linear extrapolation are >= 0. The minimum
//       knot is the one whose constrained fit is best (all are tried).
//   2D: f = 0 on the axes s_I = 0 and s_J = 0 (with the derivative along them: the data's own
//       construction, spec section 3). HYLC's published 2D splines also have f_xy = 0 on the
//       border of the grid; we leave it to the data (it would bias the border cells).
#include <string>
#include <vector>

#include "core/baked.hpp"
#include "core/dataset.hpp"

namespace yarnhom {

struct SplineFitOptions {
  int knots1d = 11;              // HYLC's materials: 11 knots per 1D term
  int knots2d = 9;               // and 8 to 10 per axis in 2D
  double smoothing = 1e-5;       // lambda
  double gradient_weight = 1.0;  // w_g
  bool monotone = true;          // the 1D monotonicity constraint
};

// One axis of a knot grid: n knots lower + k h, h = (upper - lower)/(n - 1); zero = the index of
// the knot at 0, or -1.
struct KnotAxis {
  double lower = 0, upper = 1;
  int n = 2, zero = -1;
  double spacing() const { return (upper - lower) / (n - 1); }
};

// The knots for data on [lower, upper]: when lower < 0 < upper, a knots below 0 and n - 1 - a
// above, with the a that needs the smallest spacing to cover both sides (the grid may extend
// past the data on one side by less than one spacing); otherwise n uniform knots on the data.
KnotAxis choose_knots(double lower, double upper, int n);

// Hermite basis of one axis at x: the m-th derivative (m <= 2) of the spline is
// sum_k w[k] * c(knot[k], kind[k]) with kind 0 the knot value, kind 1 the knot slope times the
// spacing; outside the knots, the linear extension. Returns the number of terms (2 or 4).
int hermite_axis_terms(const KnotAxis& ax, double x, int m, int knot[4], int kind[4], double w[4]);

struct SplineFitReport {
  std::string term;
  int knots[2] = {0, 0};
  int minimum_knot = -1;         // 1D monotone fits: the knot of the minimum
  double energy_rmse_rel = 0;    // energy RMSE / data range
  double gradient_err_rel = 0;   // mean |grad error| / mean |grad| (box-normalized units)
  int constraints_active = 0;    // 1D: monotonicity constraints that bind
};

// Fits one term. Throws std::invalid_argument for data it cannot fit (fewer than 2 samples).
BakedTable fit_spline_term(const TermData& data, const SplineFitOptions& opt, SplineFitReport* report = nullptr);

// Fits every term of a dataset into a baked model (psi0 from the dataset).
BakedModel fit_splines(const Dataset& ds, const std::string& dataset_path, const SplineFitOptions& opt,
                       std::vector<SplineFitReport>* reports = nullptr);

}  // namespace yarnhom
