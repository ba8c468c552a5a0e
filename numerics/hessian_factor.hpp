#pragma once
// The Newton system's matrix H (symmetric, assembled from lower-triangle triplets) and the
// Cholesky factorization of H + mu diag(|H_ii|) that each Newton iteration solves with.
//
// Dense (Eigen's blocked LLT) up to a size limit (kDenseLimit unless the caller gives one),
// sparse beyond: CHOLMOD's supernodal Cholesky (numerics/sparse_cholesky.hpp, the project's one
// sparse factorization; fill-reducing ordering and symbolic analysis redone only when the
// sparsity pattern changes). Supernodal beats Eigen's SimplicialLDLT by far once contact fills
// the factor in (a yarn strip: docs/benchmarks.md). Memory of the dense path: 8 n^2 bytes (72 MB
// at n = 3000).
//
// A low-rank term. H may come as a sparse part B plus U C U^T (U n x k dense, C k x k symmetric,
// k small): the yarn RVE's eliminated height unknown couples every height with every other
// (yarn/rve/rve.hpp), a dense block that would fill a sparse factor in completely. The dense
// path adds it to the matrix; the sparse path factors B + mu diag(|H_ii|) alone and solves with
// the Woodbury identity, (B' + U C U^T)^-1 = B'^-1 - W (I + C K)^-1 C U^T B'^-1 with W = B'^-1 U,
// K = U^T W. Positive definiteness of the whole: when B' is, H' = B'^1/2 (I + G C G^T) B'^1/2
// (G = B'^-1/2 U) is exactly when the k x k matrix I + K^1/2 C K^1/2 is (the nonzero
// eigenvalues of G C G^T are those of K^1/2 C K^1/2). A B' that is not positive definite is
// reported as a whole that is not either: U C U^T can lift at most as many negative eigenvalues
// as C has positive ones, so this differs from the dense answer only where B' has that few. For
// the RVE's height term (C with one eigenvalue of each sign) B' is the Hessian with the pinned
// vertex's height held instead of the mean height; on a flat tile the two are congruent (the
// uniform height shift between them is a rigid motion), so B' is definite exactly when the
// whole is, up to the shift's weights. Measured on the 2 x 2 stockinette under stretch, shear
// and bending (8 solves): of 109 factorizations in which B' failed, none of the whole succeeded. Each
// solve is checked against the matrix and refined once when its relative residual exceeds 1e-12.
//
// A stable pattern (stable_pattern): the sparse pattern only grows. Entries of earlier assemblies
// stay (as zeros) and the values of a new assembly go straight into the pattern when every entry
// is already there, so a set of contact pairs that changes between iterations costs a new
// symbolic analysis only when a pair never seen before appears.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

namespace yarnhom::numerics {

class HessianFactor {
 public:
  static constexpr int kDenseLimit = 3000;

  // dense_limit: the largest n factored densely (tests force the sparse path with 0).
  explicit HessianFactor(int n, int dense_limit = kDenseLimit, bool stable_pattern = false);
  ~HessianFactor();
  HessianFactor(const HessianFactor&) = delete;
  HessianFactor& operator=(const HessianFactor&) = delete;

  int size() const { return n_; }
  bool dense() const { return dense_; }

  // H from lower-triangle triplets (row >= col; duplicates summed).
  void assemble(const std::vector<Eigen::Triplet<double>>& lower);
  // H = (lower-triangle triplets) + U C U^T (see above; C symmetric, U.rows() == n).
  void assemble(const std::vector<Eigen::Triplet<double>>& lower, const Eigen::MatrixXd& U, const Eigen::MatrixXd& C);
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
