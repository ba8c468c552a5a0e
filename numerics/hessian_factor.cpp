#include "numerics/hessian_factor.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cstdint>
#include <stdexcept>

#include "numerics/sparse_cholesky.hpp"

namespace yarnhom::numerics {

namespace {
using Triplet = Eigen::Triplet<double>;
}

struct HessianFactor::Impl {
  // dense path: the lower triangle of H, and the factor of the shifted matrix
  Eigen::MatrixXd H;
  Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt;
  // sparse path: CHOLMOD's supernodal Cholesky (numerics/sparse_cholesky.hpp)
  Eigen::SparseMatrix<double> Hs, shifted;
  SparseCholesky sparse{SolverKind::Cholmod};
  Eigen::VectorXd diag;  // |H_ii|, floored
  bool stable = false;
  std::vector<int> diag_pos;  // stable pattern: where each diagonal entry sits in Hs's values
  std::vector<int64_t> slot_key;  // stable pattern: (row, col) of the i-th triplet last time,
  std::vector<int> slot;          // and where in Hs's values it went
  // The low-rank term U C U^T (k = U.cols() = 0: none) and, on the sparse path, what the
  // Woodbury solve needs: W = B'^-1 U and the LU of I + C K.
  Eigen::MatrixXd U, C, W;
  Eigen::PartialPivLU<Eigen::MatrixXd> small;
  bool woodbury_path = false;  // the last successful factor() was B' with the low-rank term

  int rank() const { return static_cast<int>(U.cols()); }
  void assemble_sparse(const std::vector<Triplet>& lower);
  bool scatter(const std::vector<Triplet>& lower, std::vector<Triplet>* missing);
  void grow(const std::vector<Triplet>& extra);
  bool factor_low_rank();
  Eigen::VectorXd woodbury(const Eigen::VectorXd& b) const;
};

// The sparse pattern, the values of `lower` in it. A stable pattern keeps every entry it ever
// had, and every diagonal entry; the values are summed into it in triplet order (as
// setFromTriplets sums them), and entries it lacks are added to it first (the pattern grows).
void HessianFactor::Impl::assemble_sparse(const std::vector<Triplet>& lower) {
  if (!stable) {
    Hs.setFromTriplets(lower.begin(), lower.end());
    Hs.makeCompressed();
    return;
  }
  std::vector<Triplet> missing;
  if (Hs.nonZeros() == 0 || !scatter(lower, &missing)) {
    grow(missing.empty() ? lower : missing);
    scatter(lower, nullptr);
  }
}

// The values of `lower` summed into the pattern; false (values incomplete) when entries are
// missing, which go to `missing`.
bool HessianFactor::Impl::scatter(const std::vector<Triplet>& lower, std::vector<Triplet>* missing) {
  double* val = Hs.valuePtr();
  const int* outer = Hs.outerIndexPtr();
  const int* inner = Hs.innerIndexPtr();
  std::fill(val, val + Hs.nonZeros(), 0.0);
  // Where each triplet went last time: an assembler that emits its entries in the same order
  // finds them without a search.
  if (slot.size() < lower.size()) {
    slot_key.resize(lower.size(), -1);
    slot.resize(lower.size());
  }
  bool complete = true;
  for (size_t i = 0; i < lower.size(); ++i) {
    const Triplet& t = lower[i];
    const int64_t key = (int64_t(t.row()) << 32) | t.col();
    if (slot_key[i] != key) {
      const int* b = inner + outer[t.col()];
      const int* e = inner + outer[t.col() + 1];
      const int* p = std::lower_bound(b, e, t.row());
      if (p == e || *p != t.row()) {
        if (missing) missing->push_back(t);
        complete = false;
        continue;
      }
      slot_key[i] = key;
      slot[i] = static_cast<int>(p - inner);
    }
    val[slot[i]] += t.value();
  }
  return complete;
}

// The pattern grown by the entries of `extra` (and every diagonal entry).
void HessianFactor::Impl::grow(const std::vector<Triplet>& extra) {
  const int n = static_cast<int>(Hs.rows());
  std::vector<Triplet> all;
  all.reserve(Hs.nonZeros() + n + extra.size());
  for (int j = 0; j < n; ++j) {
    all.emplace_back(j, j, 0.0);
    for (Eigen::SparseMatrix<double>::InnerIterator it(Hs, j); it; ++it) all.emplace_back(it.row(), j, 0.0);
  }
  for (const Triplet& t : extra) all.emplace_back(t.row(), t.col(), 0.0);
  Hs.setFromTriplets(all.begin(), all.end());
  Hs.makeCompressed();
  slot_key.assign(slot_key.size(), -1);
  diag_pos.resize(n);
  const int* inner = Hs.innerIndexPtr();
  for (int j = 0; j < n; ++j)
    diag_pos[j] = static_cast<int>(std::lower_bound(inner + Hs.outerIndexPtr()[j], inner + Hs.outerIndexPtr()[j + 1], j) - inner);
}

HessianFactor::HessianFactor(int n, int dense_limit, bool stable_pattern)
    : n_(n), dense_(n <= dense_limit), impl_(std::make_unique<Impl>()) {
  impl_->stable = stable_pattern;
  if (dense())
    impl_->H.resize(n, n);
  else
    impl_->Hs.resize(n, n);
}

HessianFactor::~HessianFactor() = default;

void HessianFactor::assemble(const std::vector<Triplet>& lower) {
  Impl& m = *impl_;
  m.U.resize(n_, 0);
  m.C.resize(0, 0);
  if (dense()) {
    m.H.setZero();
    for (const auto& t : lower) m.H(t.row(), t.col()) += t.value();
    m.diag = m.H.diagonal().cwiseAbs().cwiseMax(1e-300);
    return;
  }
  m.assemble_sparse(lower);
  m.diag = m.Hs.diagonal().cwiseAbs().cwiseMax(1e-300);
}

void HessianFactor::assemble(const std::vector<Triplet>& lower, const Eigen::MatrixXd& U, const Eigen::MatrixXd& C) {
  if (U.rows() != n_ || C.rows() != U.cols() || C.cols() != U.cols())
    throw std::invalid_argument("HessianFactor: the low-rank term's U must be n x k and C k x k");
  assemble(lower);
  Impl& m = *impl_;
  if (dense()) {
    m.H.triangularView<Eigen::Lower>() += U * (0.5 * (C + C.transpose())) * U.transpose();
    m.diag = m.H.diagonal().cwiseAbs().cwiseMax(1e-300);
    return;
  }
  m.U = U;
  m.C = 0.5 * (C + C.transpose());
  m.diag = (m.Hs.diagonal() + (U * m.C).cwiseProduct(U).rowwise().sum()).cwiseAbs().cwiseMax(1e-300);
}

void HessianFactor::assemble(const Eigen::SparseMatrix<double>& lower) {
  Impl& m = *impl_;
  m.U.resize(n_, 0);
  m.C.resize(0, 0);
  if (dense()) {
    m.H = Eigen::MatrixXd(lower);
    m.diag = m.H.diagonal().cwiseAbs().cwiseMax(1e-300);
    return;
  }
  if (m.stable) {
    std::vector<Triplet> t;
    t.reserve(lower.nonZeros());
    for (int j = 0; j < n_; ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(lower, j); it; ++it) t.emplace_back(it.row(), j, it.value());
    m.assemble_sparse(t);
  } else {
    m.Hs = lower;
    m.Hs.makeCompressed();
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
  m.woodbury_path = false;
  if (!m.stable && m.rank() == 0) {
    const Eigen::SparseMatrix<double>* A = &m.Hs;
    if (mu > 0) {
      m.shifted = m.Hs;
      for (int i = 0; i < n_; ++i) m.shifted.coeffRef(i, i) += mu * m.diag[i];
      m.shifted.makeCompressed();
      A = &m.shifted;
    }
    return m.sparse.factorize(*A);
  }
  m.shifted = m.Hs;
  if (m.stable) {
    double* val = m.shifted.valuePtr();
    for (int i = 0; i < n_; ++i) val[m.diag_pos[i]] += mu * m.diag[i];
  } else {
    for (int i = 0; i < n_; ++i) m.shifted.coeffRef(i, i) += mu * m.diag[i];
    m.shifted.makeCompressed();
  }
  if (m.rank() == 0) return m.sparse.factorize(m.shifted);
  return m.factor_low_rank();
}

// B' = m.shifted factored, then the k x k test of the whole (see the header). A B' that is not
// positive definite counts as a whole that is not either.
bool HessianFactor::Impl::factor_low_rank() {
  const int n = static_cast<int>(shifted.rows()), k = rank();
  if (!sparse.factorize(shifted)) return false;
  W.resize(n, k);
  for (int c = 0; c < k; ++c) W.col(c) = sparse.solve(U.col(c));
  if (!W.allFinite()) return false;
  Eigen::MatrixXd K = U.transpose() * W;
  K = (0.5 * (K + K.transpose())).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ek(K);
  const Eigen::MatrixXd R =
      ek.eigenvectors() * ek.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() * ek.eigenvectors().transpose();
  const Eigen::MatrixXd M = Eigen::MatrixXd::Identity(k, k) + R * C * R;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> em(0.5 * (M + M.transpose()), Eigen::EigenvaluesOnly);
  if (!(em.eigenvalues().minCoeff() > 1e-13)) return false;  // B' definite, the whole not (or nearly singular)
  small.compute(Eigen::MatrixXd::Identity(k, k) + C * K);
  woodbury_path = true;
  return true;
}

// (B' + U C U^T)^-1 b by the Woodbury identity, one refinement step when the residual against
// the matrix is above 1e-12 of b.
Eigen::VectorXd HessianFactor::Impl::woodbury(const Eigen::VectorXd& b) const {
  auto apply = [&](const Eigen::VectorXd& r) {
    Eigen::VectorXd x = sparse.solve(r);
    const Eigen::VectorXd z = small.solve(C * (U.transpose() * x));
    x -= W * z;
    return x;
  };
  Eigen::VectorXd x = apply(b);
  const Eigen::VectorXd res = b - (shifted.selfadjointView<Eigen::Lower>() * x + U * (C * (U.transpose() * x)));
  if (res.norm() > 1e-12 * b.norm()) x += apply(res);
  return x;
}

Eigen::VectorXd HessianFactor::solve(const Eigen::VectorXd& b) const {
  if (dense()) return impl_->llt.solve(b);
  return impl_->woodbury_path ? impl_->woodbury(b) : impl_->sparse.solve(b);
}

int HessianFactor::analyses() const { return dense() ? 0 : impl_->sparse.analyses(); }

}  // namespace yarnhom::numerics
