#pragma once
// Block-Jacobi preconditioned conjugate gradients, the CPU twin (the GPU's: cuda/block_jacobi_pcg.cu,
// the same steps in the same order). numerics/pcg_system.hpp says why and what it takes.
//
// With M^-1 the inverse of A's 3 x 3 diagonal blocks, from x_0 = 0, r_0 = b, z_0 = M^-1 r_0, p_0 = z_0:
//   q = A p,  alpha = (r.z) / (p.q),  x += alpha p,  r -= alpha q,
//   stop when |r| <= tol |b|;  z = M^-1 r,  beta = (r.z)_new / (r.z)_old,  p = z + beta p.
// Every iterate x_k minimizes the quadratic model 1/2 x.A x - b.x over a growing Krylov space, so
// each is a descent direction of the model, and a step that stops early is a shorter Newton step,
// not a wrong one (the simulator's line search takes it from there).
#include <Eigen/Sparse>
#include <vector>

#include "numerics/pcg_system.hpp"

namespace yarnhom::numerics {

// Builds the whole symmetric matrix and its block inverses from one triangle of A (compressed,
// column-major, as SparseCholesky takes it). Keeps the map from A's entries to the CSR's while the
// pattern stays, so a simulator's every step costs a copy, not a sort. Returns false when a
// diagonal block is not positive definite (the caller shifts the diagonal, as after a failed
// factorization).
class BlockJacobiBuilder {
 public:
  // same_pattern: the caller knows the triangle has the pattern of this builder's last call
  // (SparseCholesky compares it anyway): the builder's own comparison is skipped.
  bool build(const Eigen::SparseMatrix<double>& triangle, BlockCsr& out, bool same_pattern = false);
  // Only the pattern: out's n, row_ptr, col and pattern_id, and map() for it (what a device
  // builds the rest from: PcgDevice::upload_triangle). out's val and block_inv are not written.
  void build_pattern(const Eigen::SparseMatrix<double>& triangle, BlockCsr& out, bool same_pattern = false);
  const TriangleMap& map() const { return map_; }

 private:
  // True when out holds this builder's last pattern and the triangle has it.
  bool holds(const Eigen::SparseMatrix<double>& triangle, const BlockCsr& out, bool same_pattern) const;
  std::vector<int> outer_, inner_;  // the pattern the map is for
  TriangleMap map_;                 // entry k -> its CSR slot, the mirrored slot, its place in its block
  uint64_t last_id_ = 0;            // the pattern_id this builder gave last
};

// x = A^-1 b (x of size A.n, overwritten), to the relative residual tol, at most max_iterations.
BlockPcgResult block_jacobi_pcg(const BlockCsr& A, const double* b, double* x, double tol, int max_iterations);

}  // namespace yarnhom::numerics
