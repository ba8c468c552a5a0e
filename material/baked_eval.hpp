#pragma once
// The evaluator of baked tables: value, gradient and Hessian (and third derivatives, for plots
// and checks) of one term at any strain, inside the box (Hermite interpolation) or outside it
// (the safeguard). This is what a cloth simulator links: it depends only on Eigen and on the
// baked format (core/baked.hpp), never on the networks or the training code.
//
// Inside the box. 1D: cubic Hermite on each cell from (f, f') at its two knots. 2D: bicubic
// Hermite from (f, f_x, f_y, f_xy) at the cell's four knots; C1 across cells.
//
// Outside (spec section 8; docs/bake.md, "The safeguard outside the box"). Let xc = clamp(x,
// box), dx = x - xc per axis and D_ij = d^(i+j) p / dx^i dy^j the one-sided partials of the
// table p at xc (from the cell that contains xc). Then
//   1D:        F = D_0 + D_1 dx + max(D_2, 0) dx^2/2     (the paper's quadratic, curvature
//                                                         clamped; C2 where D_2 >= 0, which
//                                                         bake's 1D end repair ensures)
//   x band:    F = D_00(y) + D_10(y) dx                    (one axis outside; likewise y)
//   corner:    F = D_00 + D_10 dx + D_01 dy + D_11 dx dy
// A 2D term is a residual Psi_IJ = Psi - Psi_I - Psi_J, zero on the axes, whose own outward
// rise means nothing physically (a Poisson coupling c s_x s_y falls outward along -s_y): only
// the total energy the simulator sees must rise outward. So every 2D table continues to first
// order along the outward normal of each edge: the residual neither bends down nor up outside,
// the total's outward curvature in a band is that of the 1D terms (>= 0), and the table inside
// the box is the network's, untouched. The bilinear corner is the only continuation that is C1
// with both adjoining bands and first order along both outward normals; along a diagonal
// corner ray (c, s) its curvature is 2 D_11 c s, so the total bends down there only where the
// outward twist is negative and larger than the 1D terms' curvatures allow (D_11^2 > K_I K_J):
// bake reports those corners per term pair (bake/pair_check.hpp) rather than changing data.
// The extension is C1 with the table (C2 in 1D); its third derivatives are 0 outside in 1D, 0
// in a corner, and in a band those of the boundary data along the edge.
//
// Tables with extrapolation "linear" (fit-splines, HYLC's convention) continue to first order
// in 1D as well: D_0 + D_1 dx. In 2D "linear" and the safeguard are now the same formula (the
// tensor product of the 1D extensions, as ARCSim-HYLC's HermiteSpline2D).
#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

#include "core/baked.hpp"

namespace yarnhom {

// One term ready to evaluate: the table re-expressed as per-cell power-basis coefficients.
struct BakedTerm {
  Term term;
  int dim = 1;
  double lo[2] = {0, 0}, hi[2] = {0, 0}, inv_h[2] = {1, 1};
  int n[2] = {1, 1};             // knots per axis
  bool linear = false;           // extrapolation "linear" rather than the safeguard
  bool legacy_safeguard = false; // 2D: the file stores the band curvatures of an older bake
                                 // (read, and continued to first order all the same)
  std::vector<double> coef;      // 1D: [n0-1][4] in u^k; 2D: [n0-1][n1-1][4][4] in u^k v^l
};

// Where the safeguard of a table departs from the paper's continuation, per side (1D: lower,
// upper; 2D: the four edges x_lower, x_upper, y_lower, y_upper). 1D: a negative end curvature
// continued as 0 (only without bake's end repair). 2D: the boundary curvature d2f/dn2 that the
// paper's quadratic would have continued is dropped (first order outside); its largest
// magnitude and the knots where it was negative (would have bent the residual down) are kept.
struct SafeguardDepartures {
  struct Side {
    int knots = 0;
    int curvature_raised = 0;       // 1D: the end's d2f < 0 continued as 0; 2D: knots with d2f/dn2 < 0
    double curvature_dropped = 0;   // 2D: largest |d2f/dn2| along the edge (physical units)
  };
  std::vector<Side> sides;
  bool first_order = false;  // 2D safeguard: first order outside (every 2D table of this bake)
  bool any() const;
};

// Builds the evaluator. Throws std::invalid_argument if the table is malformed, or if its
// stored safeguard coefficients disagree with the ones the knots imply (a corrupt or hand-
// edited file); `file` names it in the message.
BakedTerm make_baked_term(const BakedTable& table, const std::string& file = "");

// Safeguard coefficients implied by the table's knots (what write_baked stores); where it had to
// depart from the paper's continuation is written into `departures` when given.
void compute_safeguard(BakedTable& table, SafeguardDepartures* departures = nullptr);

// Sector of a point: 0 inside the box. 1D: 1 below, 2 above. 2D: 1 x-lower band, 2 x-upper,
// 3 y-lower, 4 y-upper, 5..8 corners in the order of kBakedCornerNames. Points on the box
// boundary count as inside.
int baked_sector(const BakedTerm& t, const double* s);

// 1D: value, first and second derivative.
struct BakedJet1 {
  double f, df, d2f;
};
BakedJet1 eval_baked_1d(const BakedTerm& t, double x);

// 2D: value, gradient, Hessian. The fast path a simulator calls.
struct BakedJet2 {
  double f;
  Eigen::Vector2d g;
  Eigen::Matrix2d H;
};
BakedJet2 eval_baked_2d(const BakedTerm& t, const Eigen::Vector2d& s);

// The value alone, bit for bit eval_baked_1d's / eval_baked_2d's f (the energy passes of a
// simulator's line search need no derivatives).
double eval_baked_1d_value(const BakedTerm& t, double x);
double eval_baked_2d_value(const BakedTerm& t, const Eigen::Vector2d& s);

// Every channel up to `order` (<= 3) in the layout of core/jet_layout.hpp, any dimension.
void eval_baked_jet(const BakedTerm& t, const double* s, int order, double* out);

}  // namespace yarnhom
