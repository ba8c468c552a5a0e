#include "yarn/hessian_factor.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Cholesky>
#include <algorithm>

#include "core/serial_openmp.hpp"

namespace yarnhom::yarn {

struct HessianFactor::Impl {
  // dense path: the lower triangle of H, and the factor of the shifted matrix
  Eigen::MatrixXd H;
  Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt;
  // sparse path
  Eigen::SparseMatrix<double> Hs, shifted;
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt_sparse;
  std::vector<int> last_outer, last_inner;
  Eigen::VectorXd diag;  // |H_ii|, floored
};

HessianFactor::HessianFactor(int n, int dense_limit) : n_(n), dense_(n <= dense_limit), impl_(std::make_unique<Impl>()) {
  if (dense()) {
    impl_->H.resize(n, n);
  } else {
    impl_->Hs.resize(n, n);
    // An indefinite matrix is an expected outcome here (the caller shifts and retries), not
    // something for CHOLMOD to print.
    impl_->llt_sparse.cholmod().print = 0;
  }
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
  analyze_if_new();
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
  analyze_if_new();
}

void HessianFactor::analyze_if_new() {
  Impl& m = *impl_;
  const bool same = m.last_outer.size() == size_t(n_ + 1) &&
                    std::equal(m.last_outer.begin(), m.last_outer.end(), m.Hs.outerIndexPtr()) &&
                    m.last_inner.size() == size_t(m.Hs.nonZeros()) &&
                    std::equal(m.last_inner.begin(), m.last_inner.end(), m.Hs.innerIndexPtr());
  if (!same) {
    const SerialOpenMP serial;  // CHOLMOD's own OpenMP regions (core/serial_openmp.hpp)
    m.llt_sparse.analyzePattern(m.Hs);
    ++analyses_;
    m.last_outer.assign(m.Hs.outerIndexPtr(), m.Hs.outerIndexPtr() + n_ + 1);
    m.last_inner.assign(m.Hs.innerIndexPtr(), m.Hs.innerIndexPtr() + m.Hs.nonZeros());
  }
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
    A = &m.shifted;
  }
  const SerialOpenMP serial;
  m.llt_sparse.factorize(*A);
  return m.llt_sparse.info() == Eigen::Success;
}

Eigen::VectorXd HessianFactor::solve(const Eigen::VectorXd& b) const {
  return dense() ? Eigen::VectorXd(impl_->llt.solve(b)) : Eigen::VectorXd(impl_->llt_sparse.solve(b));
}

}  // namespace yarnhom::yarn
