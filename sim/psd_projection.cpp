#include "sim/psd_projection.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace yarnhom::sim {

namespace {

// True when H + tau I admits a Cholesky factorization with tau a tiny multiple of its
// largest diagonal entry: H is then positive semi-definite up to -tau, and the projection
// would change it by at most tau per eigenvalue, below the rounding of its assembly. The
// element matrix has exact zero eigenvalues (rigid motions), hence the shift.
template <int N>
bool nearly_psd(const Eigen::Matrix<double, N, N>& H) {
  const double dmax = H.diagonal().cwiseAbs().maxCoeff();
  if (!(dmax > 0)) return dmax == 0;
  const double tau = 1e-10 * dmax;
  double L[N][N];
  for (int j = 0; j < N; ++j) {
    double d = H(j, j) + tau;
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    if (!(d > 0)) return false;
    const double ljj = std::sqrt(d);
    L[j][j] = ljj;
    for (int i = j + 1; i < N; ++i) {
      double s = H(i, j);
      for (int k = 0; k < j; ++k) s -= L[i][k] * L[j][k];
      L[i][j] = s / ljj;
    }
  }
  return true;
}

}  // namespace

template <int N>
bool project_psd(Eigen::Matrix<double, N, N>& H) {
  if (nearly_psd<N>(H)) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(H);
  const Eigen::Matrix<double, N, 1> lam = es.eigenvalues().cwiseMax(0.0);
  H = es.eigenvectors() * lam.asDiagonal() * es.eigenvectors().transpose();
  return true;
}

template bool project_psd<6>(Eigen::Matrix<double, 6, 6>&);
template bool project_psd<18>(Eigen::Matrix<double, 18, 18>&);

}  // namespace yarnhom::sim
