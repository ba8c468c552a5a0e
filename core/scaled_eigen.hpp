#pragma once
// Definiteness of a Hessian in d2Psi/ds2 units: strains and curvatures have different units, so
// its eigenvalues are compared after scaling it to unit diagonal magnitude, D H D with
// D = diag(1 / sqrt(|H_ii|)) (a diagonal congruence keeps the signs of the eigenvalues).
// One definition for the RVE's measured rest Hessian (yarn/rve/rest_hessian.hpp) and the fitted
// material's (bake/rest_check.hpp), so that the two are judged alike.
#include <Eigen/Dense>
#include <cmath>

namespace yarnhom {

struct ScaledEigen {
  Eigen::Matrix<double, 6, 1> values = Eigen::Matrix<double, 6, 1>::Zero();   // ascending
  Eigen::Matrix<double, 6, 1> weakest = Eigen::Matrix<double, 6, 1>::Zero();  // unit eigenvector of values[0]
  // Positive semi-definite up to rounding: the one stability criterion of every rest check.
  bool stable(double tolerance = 1e-9) const { return values[0] >= -tolerance; }
};

inline ScaledEigen scaled_eigen(const Eigen::Matrix<double, 6, 6>& H) {
  const Eigen::Matrix<double, 6, 6> S = 0.5 * (H + H.transpose());
  Eigen::Matrix<double, 6, 1> d;
  for (int i = 0; i < 6; ++i) d[i] = std::abs(S(i, i)) > 0 ? 1 / std::sqrt(std::abs(S(i, i))) : 1.0;
  const Eigen::Matrix<double, 6, 6> scaled = d.asDiagonal() * S * d.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(scaled);
  return {es.eigenvalues(), es.eigenvectors().col(0)};
}

}  // namespace yarnhom
