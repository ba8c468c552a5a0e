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
// box), dx = x - xc per axis, D_ij = d^(i+j) p / dx^i dy^j the one-sided partials of the table p
// at xc (from the cell that contains xc), and K(y), L(x) the band curvatures of the x and y
// edges (below). Then
//   1D:        F = D_0 + D_1 dx + max(D_2, 0) dx^2/2     (the paper's quadratic; C2 with the
//                                                         table, whose repaired end has D_2 >= 0)
//   x band:    F = D_00(y) + D_10(y) dx + K(y) dx^2/2      (one axis outside; likewise y)
//   corner:    F = D_00 + D_10 dx + D_01 dy + D_11 dx dy + K dx^2/2 + L dy^2/2
//                  + K' dx^2 dy/2 + L' dx dy^2/2           (K, K', L, L' at the corner)
// K is the boundary's d2f/dn2 (the paper's choice) where that is >= 0, clamped so that the
// energy rises outward by construction: K >= 0 along the whole edge (each Hermite piece of it
// non-negative), K non-decreasing toward each corner (K' oriented outward >= 0 there), and at
// each corner K L >= D_11^2 when D_11 bends the corner's outward quadrant downward. Together
// with an outward slope D_10 >= 0 on the boundary (bake's boundary repair,
// bake/boundary_repair.hpp), the energy and its outward slope are non-decreasing along every
// outward ray: perpendicular to an edge in a band, any direction of the corner's quadrant in a
// corner. The two cubic corner terms are what C1 across the corner/edge-band borders needs (on
// the border dy = 0 the band's dF/dy is D_01 + D_11 dx + K' dx^2/2). The whole extension is C1
// (C2 in 1D) with the table; its third derivatives are 0 in 1D and constant in a corner; in a
// band they are those of the boundary data along the edge, growing at most quadratically
// with dx.
//
// Tables with extrapolation "linear" (fit-splines, HYLC's convention) continue to first order
// only: F = sum_{i<=1} D_i dx^i per outside axis, i.e. D_0 + D_1 dx in 1D, D_00(y) + D_10(y) dx
// in an edge band, D_00 + D_10 dx + D_01 dy + D_11 dx dy in a corner (the tensor product of the
// 1D extensions, as ARCSim-HYLC's HermiteSpline2D). C1 with the table; second derivatives
// across the box boundary jump to their outside values (0 along the outside axis).
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
  std::vector<double> coef;      // 1D: [n0-1][4] in u^k; 2D: [n0-1][n1-1][4][4] in u^k v^l
  // 2D: the band curvature of each edge (x_lower, x_upper, y_lower, y_upper) as (K_j, K'_j) at
  // the knots along it, interpolated by cubic Hermite between them.
  std::array<std::vector<double>, 4> band;
};

// Where the safeguard of a table departs from the paper's continuation (the raw boundary
// curvature continued): counted over the boundary knots, per side (1D: lower, upper; 2D: the
// four edges in the order above) and per corner.
struct SafeguardDepartures {
  struct Side {
    int knots = 0;
    int curvature_raised = 0;  // knots where d2f/dn2 < 0 was raised to 0 (or for convexity)
    int slope_limited = 0;     // knots whose curvature slope along the edge was limited
  };
  std::vector<Side> sides;
  int corners_convexified = 0;  // corners where K, L were raised so that K L >= D_11^2
  int corner_cubics_dropped = 0;  // corner cubic terms whose sign would bend the energy down
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

// Every channel up to `order` (<= 3) in the layout of core/jet_layout.hpp, any dimension.
void eval_baked_jet(const BakedTerm& t, const double* s, int order, double* out);

}  // namespace yarnhom
