#include "sim/psd_projection.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace yarnhom::sim {

namespace {

// True when H + tau I admits a Cholesky factorization with tau a tiny multiple of its
// largest diagonal entry: H is then positive semi-definite up to -tau, and the projection
// would change it by at most tau per eigenvalue, below the rounding of its assembly. The
// element matrix has exact zero eigenvalues (rigid motions), hence the shift.
bool nearly_psd(const Eigen::Matrix<double, 18, 18>& H) {
  const double dmax = H.diagonal().cwiseAbs().maxCoeff();
  if (!(dmax > 0)) return dmax == 0;
  const double tau = 1e-10 * dmax;
  double L[18][18];
  for (int j = 0; j < 18; ++j) {
    double d = H(j, j) + tau;
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    if (!(d > 0)) return false;
    const double ljj = std::sqrt(d);
    L[j][j] = ljj;
    for (int i = j + 1; i < 18; ++i) {
      double s = H(i, j);
      for (int k = 0; k < j; ++k) s -= L[i][k] * L[j][k];
      L[i][j] = s / ljj;
    }
  }
  return true;
}

}  // namespace

bool project_psd(Eigen::Matrix<double, 18, 18>& H) {
  if (nearly_psd(H)) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 18, 18>> es(H);
  Eigen::Matrix<double, 18, 1> lam = es.eigenvalues().cwiseMax(0.0);
  H = es.eigenvectors() * lam.asDiagonal() * es.eigenvectors().transpose();
  return true;
}

}  // namespace yarnhom::sim
