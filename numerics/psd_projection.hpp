#pragma once
// Projection of a symmetric matrix onto the positive semi-definite cone (negative eigenvalues
// set to zero), so that an assembled Newton matrix is positive semi-definite and every Newton
// direction descends (the projected Newton method of Teran et al. 2005 and IPC). One
// implementation for both simulators: sim's element Hessians (18 x 18) and material
// Hessians (6 x 6), and a yarn strip's stretch (6), bend-twist (11) and contact (12) stencils.
//
// Most matrices near equilibrium are already PSD, so a Cholesky-type test comes first and
// skips the eigen-decomposition (measured on a strip: projecting every stencil with the
// eigensolver was half of the assembly time). The test factors H + tau I with tau a tiny
// multiple (1e-10) of H's largest diagonal entry: when that succeeds, H is PSD up to -tau and
// the projection would change it by at most tau per eigenvalue, below the rounding of its
// assembly. Element matrices have exact zero eigenvalues (rigid motions), hence the shift.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>

namespace yarnhom::numerics {

// True when H + 1e-10 max|H_ii| I has a Cholesky factor (H is PSD to rounding).
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

// Projects H in place; returns true when H was changed (false: PSD already, H untouched).
template <int N>
bool project_psd(Eigen::Matrix<double, N, N>& H) {
  if (nearly_psd<N>(H)) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(H);
  const Eigen::Matrix<double, N, 1> lam = es.eigenvalues().cwiseMax(0.0);
  H = es.eigenvectors() * lam.asDiagonal() * es.eigenvectors().transpose();
  return true;
}

}  // namespace yarnhom::numerics
