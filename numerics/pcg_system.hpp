#pragma once
// What both twins of the block-Jacobi preconditioned conjugate gradients take
// (numerics/block_jacobi_pcg.hpp on the CPU, cuda/block_jacobi_pcg.cu on the GPU), and the hook
// through which a room above numerics/ lends SparseCholesky its GPU twin. No Eigen here: the
// .cu files include it (docs/layout.md, "Compiler flags").
//
// The system is the continuum simulator's step matrix A = M / h^2 + K (symmetric positive
// definite after the PSD projection of K), 3 unknowns per vertex. The preconditioner is the
// inverse of A's 3 x 3 diagonal blocks (block Jacobi): cheap to build and to apply, and
// parallel to the last row, which is what a GPU needs; a factorization's fill is what makes the
// direct solve cost ~160 ms at 16k triangles on 2 cores (docs/benchmarks.md).
#include <cstdint>
#include <memory>
#include <vector>

namespace yarnhom::numerics {

struct BlockCsr {
  int n = 0;                      // unknowns, a multiple of 3
  std::vector<int> row_ptr, col;  // the whole symmetric matrix, CSR (both triangles)
  std::vector<double> val;
  std::vector<double> block_inv;  // [n / 3][3][3], row-major: the inverses of A's diagonal blocks
  // The pattern's identity: a number no other pattern built in this process has (the builder
  // takes a new one whenever it writes row_ptr and col), so a consumer that has seen it knows
  // the pattern without comparing millions of indices.
  uint64_t pattern_id = 0;
};

// Where the entries of one triangle of A (compressed column-major, as SparseCholesky takes it)
// go in a BlockCsr: entry k to val[pos[k]] and, off the diagonal, to val[mirror[k]] too; an entry
// of a diagonal block (diag[k] = b * 9 + 3 i + j, else -1) to block b's (i, j) and (j, i).
struct TriangleMap {
  std::vector<int> pos, mirror, diag;
};

struct BlockPcgResult {
  int iterations = 0;
  double relative_residual = 0;  // |b - A x| / |b| at the end (1 for b = 0 is reported as 0)
  bool converged = false;        // relative_residual <= the tolerance
  bool breakdown = false;        // p . A p <= 0 met: A is not positive definite along p
};

// The GPU twin's interface (implemented in cuda/, registered from a room above it).
class PcgDevice {
 public:
  virtual ~PcgDevice() = default;
  // Copies the system to the device; the pattern (row_ptr, col) is uploaded again only when its
  // pattern_id differs from the last one's (0: always).
  virtual void upload(const BlockCsr& A) = 0;
  // The same system built on the device from the triangle's nnz values (host array): the pattern
  // (A's n, row_ptr, col, pattern_id; its val and block_inv are not read) and the map uploaded
  // when the pattern_id changes, the values scattered and the diagonal blocks inverted there
  // (the builder's arithmetic: a 3 x 3 Cholesky factor, its inverse). Half the bytes of upload's
  // copy, and no pass over them on the host. False when a diagonal block is not positive
  // definite (as BlockJacobiBuilder::build).
  virtual bool upload_triangle(const BlockCsr& A, const TriangleMap& map, const double* values, int nnz) = 0;
  // x = A^-1 b to the relative residual tol (host arrays of n), at most max_iterations.
  virtual BlockPcgResult solve(const double* b, double* x, double tol, int max_iterations) = 0;
  virtual const char* name() const = 0;
};
using PcgDeviceFactory = std::unique_ptr<PcgDevice> (*)();
// Set once by the program (sim/ when the build has CUDA); null when there is no GPU twin.
void register_pcg_device(PcgDeviceFactory factory);
PcgDeviceFactory pcg_device_factory();

}  // namespace yarnhom::numerics
