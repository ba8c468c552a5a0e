#pragma once
// Preconditioned conjugate gradients for a symmetric positive-definite system A x = b, with the
// product by A and the preconditioner's solve given as functions: the simulator's Newton solve
// uses it with the freshly assembled matrix and an earlier iteration's Cholesky factor as the
// preconditioner (sim/newton.hpp, "Factor reuse").
//
// From x_0 = 0: r_0 = b, z_0 = M^-1 r_0, d_0 = z_0; each iteration k = 1, 2, ... takes one product
// q = A d and one preconditioner solve z_k = M^-1 r_k. After each iteration stop(x_k, z_k) is
// asked whether x_k is good enough: z_k = M^-1 (b - A x_k) is the error's estimate when M is
// close to A (exact when M = A, where one iteration gives x_1 = A^-1 b and z_1 = 0). Every
// iterate minimizes the quadratic 1/2 x^T A x - b^T x over its Krylov space, so b^T x_k > 0:
// with b = -g the iterate is a descent direction of the energy whose gradient is g.
// A curvature d^T A d <= 0 (A not positive definite) or a non-finite value stops it, not converged.
#include <Eigen/Core>

#include <functional>

namespace yarnhom::numerics {

struct PcgResult {
  Eigen::VectorXd x;        // the last iterate (0 before the first)
  int iterations = 0;       // products with A (preconditioner solves: iterations + 1)
  bool converged = false;   // stop() accepted x
};

PcgResult pcg(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& apply_A,
              const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& apply_M_inverse, const Eigen::VectorXd& b,
              int max_iterations, const std::function<bool(const Eigen::VectorXd& x, const Eigen::VectorXd& z)>& stop);

}  // namespace yarnhom::numerics
