#pragma once
// Least squares under linear inequality constraints, for the small dense problems of the
// spline baseline (accuracy/spline_fit.hpp: a few dozen unknowns):
//
//   minimize |E x - f|^2   subject to   G x >= h
//
// by Lawson and Hanson's reduction (Solving Least Squares Problems, 1974, ch. 23): with the
// thin QR factorization E = Q R and c = Q^T f, z = R x - c turns the objective into |z|^2 + const,
// so the problem becomes least distance programming (min |z| s.t. G R^-1 z >= h - G R^-1 c),
// whose solution follows from one non-negative least squares problem (ch. 23, Theorem 23.27):
//   u = argmin_{u >= 0} |A u - b|,  A = [ (G R^-1)^T ; (h - G R^-1 c)^T ],  b = (0, ..., 0, 1);
//   r = A u - b;  r = 0 means the constraints are infeasible, otherwise z = -r_{1..n} / r_{n+1}.
// E must have full column rank (the spline fit adds a smoothing term, which guarantees it).
#include <Eigen/Dense>

namespace yarnhom {

// Non-negative least squares, min |A x - b| s.t. x >= 0 (Lawson-Hanson active set, ch. 23).
Eigen::VectorXd nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b);

struct LsiResult {
  Eigen::VectorXd x;
  bool feasible = true;  // false: no x satisfies G x >= h (x is then the unconstrained optimum)
};

// G may have zero rows (no constraints): then this is plain least squares.
LsiResult solve_lsi(const Eigen::MatrixXd& E, const Eigen::VectorXd& f, const Eigen::MatrixXd& G,
                    const Eigen::VectorXd& h);

}  // namespace yarnhom
