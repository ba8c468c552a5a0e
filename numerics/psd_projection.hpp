#pragma once
// Projection of a symmetric matrix onto the positive semi-definite cone (negative eigenvalues
// set to zero), so that an assembled Newton matrix is positive semi-definite and every Newton
// direction descends (the projected Newton method of Teran et al. 2005 and IPC). One
// implementation for both simulators: sim's element Hessians (18 x 18) and material
// Hessians (6 x 6), and a yarn strip's stretch (6), bend-twist (11) and contact (12) stencils.
//
// Most matrices near equilibrium are already PSD, so a pivoted LDL^T comes first (Sylvester:
// the signs of D are those of the eigenvalues) and skips the eigen-decomposition when no pivot
// is below -1e-12 of the largest (measured on a strip: projecting every stencil with the
// eigensolver was half of the assembly time). Element matrices have exact zero eigenvalues
// (rigid motions), which the tolerance lets through. A matrix whose smallest eigenvalue turns
// out >= 0 is left untouched (not rebuilt from its eigenvectors, which would only add rounding).
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace yarnhom::numerics {

// True when H is PSD to rounding by its LDL^T pivots: none below -1e-12 of H's largest
// diagonal entry, and none above it. Eigen's LDL^T pivots on the diagonal alone, so the first
// pivot is that largest entry and, for a PSD matrix, no later pivot exceeds it (each is a
// diagonal entry of a PSD Schur complement). A larger one is growth: a pivot at rounding level
// against an off-diagonal entry that is not, which only an indefinite matrix has. (Measured
// with the tolerance taken from the largest pivot instead: a self-collision stencil of the
// README demo's drape, eigenvalue -24 against a norm of 1,140, had pivots 67.6, ..., -0.004,
// ..., 1.3e13 and passed, was left unprojected, and made the Newton matrix indefinite: the
// step's factorization failed until the diagonal shift reached 0.1-1 of its mean, whose tiny
// step then passed the convergence test.)
template <int N>
bool nearly_psd(const Eigen::Matrix<double, N, N>& H) {
  const Eigen::LDLT<Eigen::Matrix<double, N, N>> ldlt(H);
  if (ldlt.info() != Eigen::Success) return false;
  const auto& D = ldlt.vectorD();
  const double s = H.diagonal().cwiseAbs().maxCoeff();
  return D.minCoeff() >= -1e-12 * s && D.cwiseAbs().maxCoeff() <= (1 + 1e-9) * s;
}

// What becomes of a negative eigenvalue. Clamp: 0 (the projection onto the PSD cone). Abs: its
// absolute value (Chen et al., "Stabler Neo-Hookean Simulation: Absolute Eigenvalue Filtering
// for Projected Newton", SIGGRAPH 2024): a direction of negative curvature keeps a curvature of
// its size instead of none, so the Newton step along it is not left unbounded by the element
// and cut back by the line search. On a curling stockinette's hang it cut the Newton iterations
// from 7.8 to 4.7 per step (docs/sim.md, `sim --eigen-filter abs`); the default stays Clamp.
enum class EigenFilter { Clamp, Abs };

// Projects H in place; returns true when H was changed (false: PSD already, H untouched).
template <int N>
bool project_psd(Eigen::Matrix<double, N, N>& H, EigenFilter filter = EigenFilter::Clamp) {
  if (nearly_psd<N>(H)) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(H);
  if (es.eigenvalues()[0] >= 0) return false;
  if (filter == EigenFilter::Abs)
    H = es.eigenvectors() * es.eigenvalues().cwiseAbs().asDiagonal() * es.eigenvectors().transpose();
  else
    H = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
  return true;
}

}  // namespace yarnhom::numerics
