#pragma once
// Lagged smooth friction between cloth vertices and the analytic colliders (Li et al. 2020,
// "Incremental Potential Contact", section 5; the IPC Toolkit's smoothed friction).
//
// At the start of a step (positions x^t) every free vertex k closer than dhat to a collider c
// whose coefficient mu_c > 0 is a contact with, held fixed ("lagged") during the step's solve:
//   lambda_k  the normal force the barrier exerts there, kappa A_k |b'(d(x_k^t))| (N);
//   T_k       an orthonormal 3 x 2 basis of the collider's tangent plane at x_k^t.
// The step's tangential displacement u_k = T_k^T (x_k - x_k^t) (2-vector, m) enters the
// potential through
//   D_k(x) = mu_c lambda_k f0(|u_k|),
//   f0(y) = -y^3/(3 eps^2) + y^2/eps + eps/3   for y < eps,   y   for y >= eps,
// with eps = eps_v h: below the velocity eps_v the force mu lambda f1(y), f1 = f0', ramps
// C1-smoothly from 0 (y = 0) to mu lambda (y = eps) and stays there (Coulomb's cone). Static
// friction is therefore approximated by a creep below eps_v (test Friction.*). Its stationarity
// adds to implicit Euler the Coulomb force -mu lambda f1(|u|) T u/|u| with the sliding
// direction taken over the step: the friction of IPC, exact for a fixed normal force and basis.
//
// Derivatives (y = |u|):
//   dD/dx  = mu lambda (f1(y)/y) T u,
//   d2D/dx2 = mu lambda T [ (f1(y)/y) I + (f1'(y) - f1(y)/y) u u^T / y^2 ] T^T,
// where f1(y)/y = 2/eps - y/eps^2 and f1'(y) - f1(y)/y = -y/eps^2 below eps, and f1/y = 1/y,
// f1' = 0 beyond. The 2 x 2 matrix in brackets has the eigenvalues f1(y)/y (across u) and f1'(y)
// (along u), both >= 0 for y <= eps and f1' = 0 beyond: it is positive semi-definite as it
// stands, so "projected as IPC does" clamps nothing; it is still clamped, to stay PSD under
// rounding. u = 0 is regular: f1(y)/y -> 2/eps and the u u^T term vanishes.
//
// In a static (load-step) solve there is no time step: u is measured from the previous load
// step's equilibrium and eps is a displacement, eps_v times one second.
#include <Eigen/Core>
#include <vector>

#include "sim/problem.hpp"

namespace yarnhom::sim {

// IPC's mollifier f0 and the two ratios its derivatives need: f1(y)/y and (f1'(y) - f1(y)/y)/y^2
// (the coefficient of u u^T in the Hessian); y >= 0, eps > 0.
struct FrictionMollifier {
  double f0 = 0, f1_over_y = 0, uu_coeff = 0;
};
FrictionMollifier friction_mollifier(double y, double eps);

// One lagged contact: vertex, collider, mu lambda (N), the tangent basis and the start position.
struct FrictionContact {
  int vertex = 0;
  int collider = 0;
  double mu_lambda = 0;
  Eigen::Matrix<double, 3, 2> T = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Vector3d x_start = Eigen::Vector3d::Zero();
};

// An orthonormal basis of the plane perpendicular to the unit vector n (3 x 2).
Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& n);

// D of one contact at the vertex position xv; gradient and Hessian (3 x 3, PSD) in xv if asked.
double friction_energy(const FrictionContact& c, const Eigen::Vector3d& xv, double eps, Eigen::Vector3d* grad = nullptr,
                       Eigen::Matrix3d* hess = nullptr);

// The contacts at positions x (3n): every vertex with free_index[v] >= 0 (all when free_index
// is empty) within dhat of a collider whose friction is positive. lambda and T are taken at
// x_at (the step's start, or a later iterate when the lag is updated); u is measured from x_start.
std::vector<FrictionContact> friction_contacts(const Problem& P, const std::vector<int>& free_index,
                                               const Eigen::VectorXd& x_at, const Eigen::VectorXd& x_start);

// True when some collider of P has a positive friction coefficient.
bool has_friction(const Problem& P);

}  // namespace yarnhom::sim
