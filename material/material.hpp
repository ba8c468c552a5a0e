#pragma once
// The full material (spec section 8b): Psi(s) of the 6-vector s = (s_x, s_a, s_y, II_x, II_a,
// II_y) with its gradient and Hessian in s, from the baked tables. Like material/baked_eval.hpp it
// depends only on Eigen and the baked format: this is the call a cloth simulator makes.
//
//   Psi = Psi0 + Psi_0(s_x) + Psi_1(s_a) + Psi_2(s_y) + Psi_01 + Psi_02 + Psi_12   (in-plane)
//       + B_3[Psi_3] + B_5[Psi_5] + sum_{I in 0,1,2} (B_3[Psi_I3(s_I, .)] + B_5[Psi_I5(s_I, .)])
//
// Bending enters through the principal curvatures l1 >= l2 of K = [[II_x, II_a], [II_a, II_y]]
// and c2 = cos^2 of the angle between the x axis and the first eigenvector:
//   B_3[g] = c2 g(l1) + (1 - c2) g(l2) = [g(K)]_00,   B_5[g] = c2 g(l2) + (1 - c2) g(l1) = [g(K)]_11,
// the diagonal entries of the matrix function g(K), which are smooth in K even where l1 = l2.
// With m = (II_x + II_y)/2, d = (II_x - II_y)/2, r = sqrt(d^2 + II_a^2) (l1,2 = m +- r,
// c2 = (1 + d/r)/2):
//   B_3[g] = S + d A,  B_5[g] = S - d A,   S = (g(m+r) + g(m-r))/2,  A = (g(m+r) - g(m-r))/(2r).
// S and A are even in r, hence smooth functions of rho = r^2; their derivatives in (m, rho)
// have closed forms in g, g', g'' at m +- r with powers of 1/r, which cancel catastrophically as
// r -> 0. Near an umbilic point (r below a hundredth of the table's knot spacing) we use their
// Taylor series in rho instead, from the jet of g at m: exact when g is a cubic on [m-r, m+r],
// as a baked table is within a cell. That is how umbilic points are handled.
#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include "material/baked_eval.hpp"
#include "material/strain.hpp"
#include "core/baked.hpp"

namespace yarnhom {


struct BakedMaterial {
  double psi0 = 0.0;
  double areal_density = NAN;  // kg/m^2 (gravity, inertia); NaN: the baked file does not say
  std::array<std::optional<BakedTerm>, 14> terms;  // in the order of all_terms(); absent: 0
};

// Builds every table's evaluator (checking its safeguard coefficients). Missing terms count as
// zero; `missing` (if given) receives their names.
BakedMaterial make_baked_material(const BakedModel& m, const std::string& file = "",
                                  std::string* missing = nullptr);

struct MaterialEval {
  double psi = 0.0;
  Strain6 grad = Strain6::Zero();
  Eigen::Matrix<double, 6, 6> hess = Eigen::Matrix<double, 6, 6>::Zero();
};

MaterialEval eval_material(const BakedMaterial& mat, const Strain6& s);
// Psi alone, bit for bit eval_material's psi (the same terms, in the same order, by the same
// operations; the tables' derivatives and the curvature mixing's are not computed): what an
// energy evaluation needs, at a fraction of the cost.
double eval_material_value(const BakedMaterial& mat, const Strain6& s);

// One bending term alone, for tests: the [g(K)]_00 (which = 3) or [g(K)]_11 (which = 5) part
// of a term. For a 1D term p is ignored. Returns value, gradient and Hessian in (p, II_x,
// II_a, II_y).
struct BendingEval {
  double value = 0.0;
  Eigen::Vector4d grad = Eigen::Vector4d::Zero();
  Eigen::Matrix4d hess = Eigen::Matrix4d::Zero();
};
BendingEval eval_bending(const BakedTerm& t, int which, double p, double IIx, double IIa, double IIy);
// Its value alone, bit for bit.
double eval_bending_value(const BakedTerm& t, int which, double p, double IIx, double IIa, double IIy);

// The same mixing for a curvature function that is not a baked table (HYLC's splines,
// material/hylc_material.hpp): jet(p, l, order, out) writes the term's jet at (p, l) (1D: at l, p
// ignored) in the layout of core/jet_layout.hpp, up to order 3. tau: the radius r below which
// the umbilic series is used; the series is exact where the term is a cubic in the curvature
// on [m - r, m + r], so tau should be a small fraction (the baked tables use 1e-2) of the
// shortest spline interval.
using CurvatureJet = std::function<void(double p, double l, int order, double* out)>;
BendingEval eval_bending_general(const CurvatureJet& jet, bool two_d, double tau, int which, double p, double IIx,
                                 double IIa, double IIy);

}  // namespace yarnhom
