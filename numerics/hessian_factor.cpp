#include "numerics/hessian_factor.hpp"

#include <Eigen/Cholesky>
#include <algorithm>

#include "numerics/sparse_cholesky.hpp"

namespace yarnhom::numerics {

struct HessianFactor::Impl {
  // dense path: the lower triangle of H, and the factor of the shifted matrix
  Eigen::MatrixXd H;
  Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt;
  // sparse path: CHOLMOD's supernodal Cholesky (numerics/sparse_cholesky.hpp)
  Eigen::SparseMatrix<double> Hs, shifted;
  SparseCholesky sparse{SolverKind::Cholmod};
  Eigen::VectorXd diag;  // |H_ii|, floored
};

HessianFactor::HessianFactor(int n, int dense_limit) : n_(n), dense_(n <= dense_limit), impl_(std::make_unique<Impl>()) {
  if (dense())
    impl_->H.resize(n, n);
  else
    impl_->Hs.resize(n, n);
}

HessianFactor::~HessianFactor() = default;

void HessianFactor::assemble(const std::vector<Eigen::Triplet<double>>& lower) {
  Impl& m = *impl_;
  if (dense()) {
    m.H.setZero();
    for (const auto& t : lower) m.H(t.row(), t.col()) += t.value();
    m.diag = m.H.diagonal().cwiseAbs().cwiseMax(1e-300);
    return;
  }
  m.Hs.setFromTriplets(lower.begin(), lower.end());
  m.Hs.makeCompressed();
  m.diag = m.Hs.diagonal().cwiseAbs().cwiseMax(1e-300);
}

void HessianFactor::assemble(const Eigen::SparseMatrix<double>& lower) {
  Impl& m = *impl_;
  if (dense()) {
    m.H = Eigen::MatrixXd(lower);
    m.diag = m.H.diagonal().cwiseAbs().cwiseMax(1e-300);
    return;
  }
  m.Hs = lower;
  m.Hs.makeCompressed();
  m.diag = m.Hs.diagonal().cwiseAbs().cwiseMax(1e-300);
}

bool HessianFactor::factor(double mu) {
  Impl& m = *impl_;
  if (dense()) {
    if (mu > 0) {
      Eigen::MatrixXd A = m.H;
      A.diagonal() += mu * m.diag;
      m.llt.compute(A);
    } else {
      m.llt.compute(m.H);
    }
    return m.llt.info() == Eigen::Success;
  }
  const Eigen::SparseMatrix<double>* A = &m.Hs;
  if (mu > 0) {
    m.shifted = m.Hs;
    for (int i = 0; i < n_; ++i) m.shifted.coeffRef(i, i) += mu * m.diag[i];
    m.shifted.makeCompressed();
    A = &m.shifted;
  }
  return m.sparse.factorize(*A);
}

Eigen::VectorXd HessianFactor::solve(const Eigen::VectorXd& b) const {
  return dense() ? Eigen::VectorXd(impl_->llt.solve(b)) : impl_->sparse.solve(b);
}

int HessianFactor::analyses() const { return dense() ? 0 : impl_->sparse.analyses(); }

}  // namespace yarnhom::numerics
