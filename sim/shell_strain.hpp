#pragma once
// The strain 6-vector of one triangle (spec section 2), s = (s_x, s_a, s_y, II_x, II_a, II_y),
// with its exact Jacobian in the element's 18 coordinates q = (x0, x1, x2, f0, f1, f2) and the
// Hessian contracted with a weight 6-vector lambda, sum_k lambda_k d2s_k/dq2 (what the chain
// rule of an energy Psi(s) needs, with lambda = dPsi/ds). theta_ref: the branches of the three
// dihedral angles (sim/second_fundamental_form.hpp), or null for (-pi, pi].
#include "material/strain.hpp"
#include "sim/element_rest.hpp"
#include "sim/second_fundamental_form.hpp"

namespace yarnhom::sim {

using Jac6x18 = Eigen::Matrix<double, 6, 18>;

Strain6 shell_strain(const Vec18& q, const ElementRest& rest, const bool has_flap[3], Jac6x18* J = nullptr,
                     const Strain6* lambda = nullptr, Mat18* H = nullptr, const double* theta_ref = nullptr);

}  // namespace yarnhom::sim
