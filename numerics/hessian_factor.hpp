#pragma once
// The Newton system's matrix H (symmetric, assembled from lower-triangle triplets) and the
// Cholesky factorization of H + mu diag(|H_ii|) that each Newton iteration solves with.
//
// Dense (Eigen's blocked LLT) up to kDenseLimit unknowns, sparse beyond: CHOLMOD's supernodal
// Cholesky (numerics/sparse_cholesky.hpp, the project's one sparse factorization; fill-reducing
// ordering and symbolic analysis redone only when the sparsity pattern changes). Supernodal beats Eigen's SimplicialLDLT by
// far once contact fills the factor in (a yarn strip: docs/benchmarks.md). Why dense: contact couples segments across
// the whole tile, so the sparse factor fills in almost completely; measured on the paper's
// patterns (396 to 1418 unknowns) the dense factorization is 1.5x to 2.6x faster than the
// sparse one (stockinette 0.61 vs 1.11 ms, honeycomb 3.7 vs 9.2 ms, cartridge belt rib 23 vs
// 36 ms) and skips the triplet sort. Memory: 8 n^2 bytes (72 MB at the limit).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

namespace yarnhom::numerics {

class HessianFactor {
 public:
  static constexpr int kDenseLimit = 3000;

  // dense_limit: the largest n factored densely (tests force the sparse path with 0).
  explicit HessianFactor(int n, int dense_limit = kDenseLimit);
  ~HessianFactor();
  HessianFactor(const HessianFactor&) = delete;
  HessianFactor& operator=(const HessianFactor&) = delete;

  int size() const { return n_; }
  bool dense() const { return dense_; }

  // H from lower-triangle triplets (row >= col; duplicates summed).
  void assemble(const std::vector<Eigen::Triplet<double>>& lower);
  // H from its lower triangle, compressed (numerics/block_hessian.hpp assembles one directly).
  void assemble(const Eigen::SparseMatrix<double>& lower);
  // Factors H + mu diag(|H_ii|) (the diagonal floored at 1e-300); false if that matrix is not
  // positive definite (or the factorization failed), true otherwise.
  bool factor(double mu);
  // x = (H + mu diag)^-1 b with the last successful factor().
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // Symbolic analyses done (sparse path; 0 for dense).
  int analyses() const;

 private:
  struct Impl;
  int n_;
  bool dense_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace yarnhom::numerics
