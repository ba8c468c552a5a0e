#include "numerics/triplet_matrix.hpp"

#include <omp.h>

#include <cstdint>

#include "core/raw_vector.hpp"
#include "numerics/radix_sort.hpp"

namespace yarnhom::numerics {

void triplets_to_matrix(const std::vector<Eigen::Triplet<double>>& t, Eigen::Index rows, Eigen::Index cols,
                        Eigen::SparseMatrix<double>& out) {
  const int64_t n = int64_t(t.size());
  if (rows == 0 || cols == 0) {
    out.resize(rows, cols);
    return;
  }
  const bool par = n >= (int64_t(1) << 15);
  // Keys (column, row) in the triplets' order, sorted stably: equal keys keep that order.
  RawVector<uint64_t> key(static_cast<size_t>(n));
  RawVector<int64_t> from(static_cast<size_t>(n));
#pragma omp parallel for schedule(static) if (par)
  for (int64_t k = 0; k < n; ++k) {
    key[size_t(k)] = uint64_t(t[size_t(k)].col()) * uint64_t(rows) + uint64_t(t[size_t(k)].row());
    from[size_t(k)] = k;
  }
  radix_sort(key, from, key_bits(uint64_t(rows) * uint64_t(cols)), par);
  // The sorted list in parts, each beginning at a new key (a run of one key in one part): each
  // part counts its entries, then writes them from its place on.
  const int parts = par ? omp_get_max_threads() : 1;
  std::vector<int64_t> lo(size_t(parts) + 1), count(size_t(parts) + 1, 0);
  for (int p = 0; p <= parts; ++p) {
    int64_t k = n * p / parts;
    while (k > 0 && k < n && key[size_t(k)] == key[size_t(k) - 1]) ++k;
    lo[size_t(p)] = p == parts ? n : std::max<int64_t>(k, p > 0 ? lo[size_t(p) - 1] : 0);
  }
#pragma omp parallel for schedule(static, 1) num_threads(parts) if (par)
  for (int p = 0; p < parts; ++p)
    for (int64_t k = lo[size_t(p)]; k < lo[size_t(p) + 1]; ++k)
      count[size_t(p) + 1] += k == 0 || key[size_t(k)] != key[size_t(k) - 1];
  for (int p = 0; p < parts; ++p) count[size_t(p) + 1] += count[size_t(p)];
  const int64_t nnz = count[size_t(parts)];
  out.resize(rows, cols);
  out.resizeNonZeros(nnz);
  int* outer = out.outerIndexPtr();
  int* inner = out.innerIndexPtr();
  double* val = out.valuePtr();
  std::vector<int64_t> column_end(static_cast<size_t>(cols), -1);  // (written by the entry that ends a column)
#pragma omp parallel for schedule(static, 1) num_threads(parts) if (par)
  for (int p = 0; p < parts; ++p) {
    int64_t e = count[size_t(p)] - 1;
    for (int64_t k = lo[size_t(p)]; k < lo[size_t(p) + 1]; ++k) {
      const Eigen::Triplet<double>& tr = t[size_t(from[size_t(k)])];
      if (k == 0 || key[size_t(k)] != key[size_t(k) - 1]) {
        inner[++e] = int(tr.row());
        val[e] = tr.value();
      } else {
        val[e] += tr.value();
      }
      if (k + 1 == n || key[size_t(k) + 1] / uint64_t(rows) != key[size_t(k)] / uint64_t(rows)) column_end[size_t(tr.col())] = e + 1;
    }
  }
  // Column starts: a column's entries end where its last entry is; empty columns end where the
  // column before them ends.
  outer[0] = 0;
  for (Eigen::Index c = 0; c < cols; ++c) outer[c + 1] = column_end[size_t(c)] >= 0 ? int(column_end[size_t(c)]) : outer[c];
}

}  // namespace yarnhom::numerics
