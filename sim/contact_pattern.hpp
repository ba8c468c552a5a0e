#pragma once
// The Newton matrix's pattern under contact (sim/newton.cpp). Contact pairs and stitches couple
// vertices the mesh does not: their Hessian blocks come as triplets, and the matrix H + contact
// has a pattern that changes whenever a pair comes or goes. The sparse Cholesky analyses every
// new pattern afresh (fill-reducing ordering, symbolic factor: numerics/sparse_cholesky.cpp
// compares each matrix's pattern with the last one's), which is serial and costs a share of
// a step. A PaddedPattern keeps one pattern that holds the couplings of its last rebuild and
// those of every pair within a padding distance then (pad), and hands the solver the matrix
// on it: the same values, explicit zeros where a kept coupling is not active now. As long as
// the kept pattern holds the matrix's, the pattern the solver sees does not change and its
// analysis is reused; a matrix with a coupling outside it rebuilds it (its pattern plus the
// pad, taken again at the current positions). Explicit zeros change neither the factor's
// values in exact arithmetic nor the solve; they add fill where the padding couples.
#include <Eigen/Sparse>
#include <functional>
#include <utility>
#include <vector>

namespace yarnhom::sim {

class PaddedPattern {
 public:
  // Free-vertex blocks (fa > fb) to hold beyond the matrix's own couplings.
  using Pad = std::function<std::vector<std::pair<int, int>>()>;

  // A (compressed, lower triangle, every diagonal entry stored, 3 unknowns per free vertex) on the kept
  // pattern, which is rebuilt first when it does not hold A's. The result is valid until the
  // next call; its values may be changed (a diagonal shift).
  Eigen::SparseMatrix<double>& embed(const Eigen::SparseMatrix<double>& A, const Pad& pad);
  // embed(H + C) (H compressed, C any), each entry's value that of Eigen's sum (h + c, h + 0,
  // 0 + c): one pass over the columns on the OpenMP threads writes the sum straight into the
  // kept pattern (no matrix H + C formed; the same values on any thread count); where C has a
  // coupling outside it, the pattern is rebuilt from H's, C's and the pad's first.
  Eigen::SparseMatrix<double>& embed_sum(const Eigen::SparseMatrix<double>& H, const Eigen::SparseMatrix<double>& C,
                                         const Pad& pad);

  int rebuilds() const { return rebuilds_; }
  int uses() const { return uses_; }

 private:
  bool scatter(const Eigen::SparseMatrix<double>& A);  // false when A has an entry outside M_
  bool sum_into(const Eigen::SparseMatrix<double>& H, const Eigen::SparseMatrix<double>& B);  // the same for H + B
  // M_'s pattern: the union of A's, B's (when given) and the pad's full 3 x 3 blocks, built
  // column by column on the OpenMP threads (a sorted merge per column; values zero).
  void rebuild(const Eigen::SparseMatrix<double>& A, const Eigen::SparseMatrix<double>* B, const Pad& pad);
  Eigen::SparseMatrix<double> M_;
  int rebuilds_ = 0, uses_ = 0;
};

}  // namespace yarnhom::sim
