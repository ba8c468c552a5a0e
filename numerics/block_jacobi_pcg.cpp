#include "numerics/block_jacobi_pcg.hpp"

#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include "numerics/spd3_inverse.hpp"

namespace yarnhom::numerics {

namespace {
PcgDeviceFactory g_device_factory = nullptr;
// Below this many unknowns the vector operations run on the calling thread: an iteration's six
// parallel regions cost more than their work (and a descheduled thread stalls each of them).
constexpr int kParallelMin = 100000;
constexpr int kParallelEntries = 200000;  // the builder's scatter of the matrix's entries

double dot(int n, const double* a, const double* b) {
  double s = 0;
#pragma omp parallel for reduction(+ : s) schedule(static) if (n > kParallelMin)
  for (int i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}
}  // namespace

void register_pcg_device(PcgDeviceFactory factory) { g_device_factory = factory; }
PcgDeviceFactory pcg_device_factory() { return g_device_factory; }

bool BlockJacobiBuilder::holds(const Eigen::SparseMatrix<double>& T, const BlockCsr& out, bool same_pattern) const {
  const int n = int(T.rows());
  const int nnz = int(T.nonZeros());
  if (outer_.size() != size_t(n + 1) || inner_.size() != size_t(nnz) || out.n != n || out.pattern_id == 0 ||
      out.pattern_id != last_id_)
    return false;
  return same_pattern || (std::equal(outer_.begin(), outer_.end(), T.outerIndexPtr()) &&
                          std::equal(inner_.begin(), inner_.end(), T.innerIndexPtr()));
}

void BlockJacobiBuilder::build_pattern(const Eigen::SparseMatrix<double>& T, BlockCsr& out, bool same_pattern) {
  if (holds(T, out, same_pattern)) return;
  const int n = int(T.rows());
  const int nnz = int(T.nonZeros());
  const int* outer = T.outerIndexPtr();
  const int* inner = T.innerIndexPtr();
  static std::atomic<uint64_t> next_id{1};
  out.pattern_id = last_id_ = next_id++;
  outer_.assign(outer, outer + n + 1);
  inner_.assign(inner, inner + nnz);
  out.n = n;
  // Row r of the whole matrix: the triangle's entries of row r (columns c <= r) in column order,
  // then the mirrors (r, r') of column r's entries r' > r in row order: its columns ascending.
  // An entry's place among its row's first part is its rank among that row's entries of earlier
  // columns (a stable counting sort by row), found in blocks of columns on the threads: each
  // block counts its rows, the counts are summed block by block, each block places its
  // entries; the result is the same on any thread count.
  const bool par = nnz > kParallelEntries;
  const int nb = par ? std::max(1, omp_get_max_threads()) : 1;
  std::vector<int> first(size_t(nb) + 1, n);  // block b: columns [first[b], first[b + 1])
  for (int b = 0; b < nb; ++b)
    first[size_t(b)] = int(std::lower_bound(outer, outer + n, int(int64_t(nnz) * b / nb)) - outer);
  std::vector<int> rank(size_t(nb) * size_t(n), 0);  // block b's count, then its first rank, per row
#pragma omp parallel for schedule(static, 1) num_threads(nb) if (par)
  for (int b = 0; b < nb; ++b)
    for (int c = first[size_t(b)]; c < first[size_t(b) + 1]; ++c)
      for (int k = outer[c]; k < outer[c + 1]; ++k) ++rank[size_t(b) * n + inner[k]];
  std::vector<int> lower(static_cast<size_t>(n));  // each row's entries in the triangle
#pragma omp parallel for schedule(static) if (par)
  for (int r = 0; r < n; ++r) {
    int sum = 0;
    for (int b = 0; b < nb; ++b) {
      const int c = rank[size_t(b) * n + r];
      rank[size_t(b) * n + r] = sum;
      sum += c;
    }
    lower[size_t(r)] = sum;
  }
  auto has_diagonal = [&](int c) { return outer[c + 1] > outer[c] && inner[outer[c]] == c; };
  out.row_ptr.assign(size_t(n) + 1, 0);
  for (int r = 0; r < n; ++r)
    out.row_ptr[size_t(r) + 1] = out.row_ptr[size_t(r)] + lower[size_t(r)] + (outer[r + 1] - outer[r]) - (has_diagonal(r) ? 1 : 0);
  out.col.resize(size_t(out.row_ptr[size_t(n)]));
  map_.pos.resize(size_t(nnz)), map_.mirror.resize(size_t(nnz)), map_.diag.resize(size_t(nnz));
#pragma omp parallel for schedule(static, 1) num_threads(nb) if (par)
  for (int b = 0; b < nb; ++b)
    for (int c = first[size_t(b)]; c < first[size_t(b) + 1]; ++c) {
      int mirror = out.row_ptr[size_t(c)] + lower[size_t(c)];  // column c's mirrors, after row c's first part
      for (int k = outer[c]; k < outer[c + 1]; ++k) {
        const int r = inner[k];
        const int p = out.row_ptr[size_t(r)] + rank[size_t(b) * n + r]++;
        map_.pos[size_t(k)] = p;
        out.col[size_t(p)] = c;
        map_.mirror[size_t(k)] = r != c ? mirror : -1;
        if (r != c) out.col[size_t(mirror++)] = r;
        map_.diag[size_t(k)] = r / 3 == c / 3 ? (r / 3) * 9 + 3 * (r % 3) + c % 3 : -1;
      }
    }
}

bool BlockJacobiBuilder::build(const Eigen::SparseMatrix<double>& T, BlockCsr& out, bool same_pattern) {
  const int n = int(T.rows());
  const int nnz = int(T.nonZeros());
  build_pattern(T, out, same_pattern);
  if (out.val.size() != size_t(out.row_ptr[n])) out.val.assign(out.row_ptr[n], 0.0);
  if (out.block_inv.size() != size_t(3 * n)) out.block_inv.assign(3 * n, 0.0);
  const std::vector<int>&pos_ = map_.pos, &mirror_ = map_.mirror, &diag_ = map_.diag;
  const double* v = T.valuePtr();
  // The diagonal blocks are gathered into block_inv and inverted in place below. Each entry k
  // writes places of its own (its row's, its mirror's, its block's two), so the entries go on
  // the threads (the simulator's matrices: a million entries and more, scattered).
  std::vector<double>& blocks = out.block_inv;
  std::fill(blocks.begin(), blocks.end(), 0.0);
#pragma omp parallel for schedule(static) if (nnz > kParallelEntries)
  for (int k = 0; k < nnz; ++k) {
    out.val[pos_[k]] = v[k];
    if (mirror_[k] >= 0) out.val[mirror_[k]] = v[k];
    if (diag_[k] >= 0) {
      // One triangle holds (i, j) or (j, i) of a block: write both.
      const int b = diag_[k] / 9, i = (diag_[k] % 9) / 3, j = diag_[k] % 3;
      blocks[9 * b + 3 * i + j] = v[k];
      blocks[9 * b + 3 * j + i] = v[k];
    }
  }
  bool ok = true;
#pragma omp parallel for schedule(static) reduction(&& : ok) if (nnz > kParallelEntries)
  for (int b = 0; b < n / 3; ++b) ok = spd3_inverse(&blocks[9 * b], &blocks[9 * b]) && ok;
  return ok;
}

BlockPcgResult block_jacobi_pcg(const BlockCsr& A, const double* b, double* x, double tol, int max_iterations) {
  const int n = A.n, nb = n / 3;
  std::vector<double> r(b, b + n), z(n), p(n), q(n);
  std::fill(x, x + n, 0.0);
  auto precondition = [&] {
#pragma omp parallel for schedule(static) if (n > kParallelMin)
    for (int k = 0; k < nb; ++k) {
      const double* Bi = &A.block_inv[9 * k];
      const double r0 = r[3 * k], r1 = r[3 * k + 1], r2 = r[3 * k + 2];
      z[3 * k] = Bi[0] * r0 + Bi[1] * r1 + Bi[2] * r2;
      z[3 * k + 1] = Bi[3] * r0 + Bi[4] * r1 + Bi[5] * r2;
      z[3 * k + 2] = Bi[6] * r0 + Bi[7] * r1 + Bi[8] * r2;
    }
  };
  BlockPcgResult res;
  res.relative_residual = 1;
  const double bn = std::sqrt(dot(n, b, b));
  if (!(bn > 0)) {
    res.relative_residual = 0;
    res.converged = true;
    return res;
  }
  precondition();
  p = z;
  double rz = dot(n, r.data(), z.data());
  for (int it = 1; it <= max_iterations; ++it) {
#pragma omp parallel for schedule(static) if (n > kParallelMin)
    for (int i = 0; i < n; ++i) {
      double s = 0;
      for (int k = A.row_ptr[i]; k < A.row_ptr[i + 1]; ++k) s += A.val[k] * p[A.col[k]];
      q[i] = s;
    }
    const double pq = dot(n, p.data(), q.data());
    if (!(pq > 0)) {
      res.breakdown = true;
      break;
    }
    const double alpha = rz / pq;
#pragma omp parallel for schedule(static) if (n > kParallelMin)
    for (int i = 0; i < n; ++i) x[i] += alpha * p[i], r[i] -= alpha * q[i];
    res.iterations = it;
    res.relative_residual = std::sqrt(dot(n, r.data(), r.data())) / bn;
    if (res.relative_residual <= tol) {
      res.converged = true;
      break;
    }
    precondition();
    const double rz1 = dot(n, r.data(), z.data());
    const double beta = rz1 / rz;
    rz = rz1;
#pragma omp parallel for schedule(static) if (n > kParallelMin)
    for (int i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
  }
  return res;
}

}  // namespace yarnhom::numerics
