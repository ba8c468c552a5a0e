#include "sim/contact_pattern.hpp"

#include <omp.h>

#include <algorithm>
#include <cstdint>

#include "core/scope_profile.hpp"

namespace yarnhom::sim {

namespace {

// Below this many columns one thread builds and fills (a fork costs more than the work).
constexpr Eigen::Index kParallelColumns = 3072;
constexpr int64_t kParallelBlocks = 65536;  // the pad's blocks sorted on the threads from this many

// The sorted union of a few sorted row lists, written to out (null: only counted); its length.
// Column j's lists: A's rows, B's rows (B may be null), and the pad's blocks' rows (3 fa .. 3 fa + 2
// for each fa of the column's block, fa ascending).
int merge_rows(const int* a, const int* ae, const int* b, const int* be, const int* fa, const int* fae, int* out) {
  int n = 0, last = -1;
  int pr = fa < fae ? 3 * *fa : -1, pk = 0;  // the pad's next row: block *fa, row pk of 3
  auto emit = [&](int r) {
    if (r == last) return;
    if (out) out[n] = r;
    ++n;
    last = r;
  };
  while (a < ae || b < be || pr >= 0) {
    int r = INT32_MAX;
    if (a < ae) r = std::min(r, *a);
    if (b < be) r = std::min(r, *b);
    if (pr >= 0) r = std::min(r, pr);
    emit(r);
    if (a < ae && *a == r) ++a;
    if (b < be && *b == r) ++b;
    if (pr == r) {
      if (++pk == 3) {
        pk = 0;
        pr = ++fa < fae ? 3 * *fa : -1;
      } else {
        ++pr;
      }
    }
  }
  return n;
}

}  // namespace

bool PaddedPattern::scatter(const Eigen::SparseMatrix<double>& A) {
  if (M_.rows() != A.rows() || M_.cols() != A.cols()) return false;
  const int* mo = M_.outerIndexPtr();
  const int* mi = M_.innerIndexPtr();
  double* mv = M_.valuePtr();
  const int* ao = A.outerIndexPtr();
  const int* ai = A.innerIndexPtr();
  const double* av = A.valuePtr();
  for (Eigen::Index j = 0; j < A.outerSize(); ++j) {
    int p = mo[j];
    const int end = mo[j + 1];
    for (int k = ao[j]; k < ao[j + 1]; ++k) {  // both columns sorted: one merge, zeros between
      while (p < end && mi[p] < ai[k]) mv[p++] = 0.0;
      if (p == end || mi[p] != ai[k]) return false;
      mv[p++] = av[k];
    }
    while (p < end) mv[p++] = 0.0;
  }
  return true;
}

void PaddedPattern::rebuild(const Eigen::SparseMatrix<double>& A, const Eigen::SparseMatrix<double>* B, const Pad& pad) {
  prof::Scope ps("kept pattern: rebuild");
  // The pad's blocks (fa > fb) by block column, rows ascending, each once.
  std::vector<std::pair<int, int>> blocks;
  {
    prof::Scope pp("kept pattern: its pad (pairs within 2 dhat)");
    blocks = pad();
  }
  // The pad's rows by column block: a stable counting sort (hundreds of thousands of blocks, up
  // to millions on a T-shirt), each thread counting and placing a contiguous part of the list,
  // then each column's few rows sorted and made unique. On the threads; the result depends only
  // on the set of blocks.
  const Eigen::Index n = A.cols(), nb = (n + 2) / 3;
  const int64_t nblk = int64_t(blocks.size());
  const bool par = nblk >= kParallelBlocks;
  const int T = par ? std::max(1, omp_get_max_threads()) : 1;
  auto valid = [&](const std::pair<int, int>& b) { return b.first > b.second && 3 * Eigen::Index(b.first) < A.rows(); };
  std::vector<int> rank(size_t(T) * size_t(nb), 0);  // thread u's count, then its first place, per column
#pragma omp parallel num_threads(T) if (par)
  {
    const int u = omp_get_thread_num(), nt = omp_get_num_threads();
    const int64_t lo = nblk * u / nt, hi = nblk * (u + 1) / nt;
    int* r = &rank[size_t(u) * size_t(nb)];
    for (int64_t k = lo; k < hi; ++k)
      if (valid(blocks[size_t(k)])) ++r[blocks[size_t(k)].second];
  }
  std::vector<int> count(size_t(nb) + 1, 0);  // column c's rows at [count[c], count[c + 1])
  for (Eigen::Index c = 0; c < nb; ++c) {
    int sum = count[size_t(c)];
    for (int u = 0; u < T; ++u) {
      const int k = rank[size_t(u) * size_t(nb) + size_t(c)];
      rank[size_t(u) * size_t(nb) + size_t(c)] = sum;
      sum += k;
    }
    count[size_t(c) + 1] = sum;
  }
  std::vector<int> brow(size_t(count[size_t(nb)]));
#pragma omp parallel num_threads(T) if (par)
  {
    const int u = omp_get_thread_num(), nt = omp_get_num_threads();
    const int64_t lo = nblk * u / nt, hi = nblk * (u + 1) / nt;
    int* r = &rank[size_t(u) * size_t(nb)];
    for (int64_t k = lo; k < hi; ++k)
      if (valid(blocks[size_t(k)])) brow[size_t(r[blocks[size_t(k)].second]++)] = blocks[size_t(k)].first;
  }
  std::vector<int> bstart(size_t(nb) + 1, 0), kept(static_cast<size_t>(nb));
#pragma omp parallel for schedule(dynamic, 256) if (par)
  for (Eigen::Index c = 0; c < nb; ++c) {  // sorted and unique in place
    int* b = brow.data() + count[size_t(c)];
    int* e = brow.data() + count[size_t(c) + 1];
    std::sort(b, e);
    kept[size_t(c)] = int(std::unique(b, e) - b);
  }
  for (Eigen::Index c = 0; c < nb; ++c) bstart[size_t(c) + 1] = bstart[size_t(c)] + kept[size_t(c)];
  for (Eigen::Index c = 0; c < nb; ++c)  // compacted (in place: each column moves down, in order)
    std::copy(brow.data() + count[size_t(c)], brow.data() + count[size_t(c)] + kept[size_t(c)],
              brow.data() + bstart[size_t(c)]);
  // Column by column: the union of A's, B's and the pad's rows, counted, then written.
  const int *ao = A.outerIndexPtr(), *ai = A.innerIndexPtr();
  const int *bo = B ? B->outerIndexPtr() : nullptr, *bi = B ? B->innerIndexPtr() : nullptr;
  auto column = [&](Eigen::Index j, int* out) {
    const int* pa = brow.data() + bstart[size_t(j / 3)];
    const int* pe = brow.data() + bstart[size_t(j / 3) + 1];
    return merge_rows(ai + ao[j], ai + ao[j + 1], B ? bi + bo[j] : nullptr, B ? bi + bo[j + 1] : nullptr, pa, pe, out);
  };
  std::vector<int> outer(size_t(n) + 1, 0);
#pragma omp parallel for schedule(static) if (n >= kParallelColumns)
  for (Eigen::Index j = 0; j < n; ++j) outer[size_t(j) + 1] = column(j, nullptr);
  for (Eigen::Index j = 0; j < n; ++j) outer[size_t(j) + 1] += outer[size_t(j)];
  M_.resize(A.rows(), n);
  M_.makeCompressed();
  M_.resizeNonZeros(outer[size_t(n)]);
  std::copy(outer.begin(), outer.end(), M_.outerIndexPtr());
  int* mi = M_.innerIndexPtr();
  double* mv = M_.valuePtr();
#pragma omp parallel for schedule(static) if (n >= kParallelColumns)
  for (Eigen::Index j = 0; j < n; ++j) {
    column(j, mi + outer[size_t(j)]);
    std::fill(mv + outer[size_t(j)], mv + outer[size_t(j) + 1], 0.0);
  }
  ++rebuilds_;
}

Eigen::SparseMatrix<double>& PaddedPattern::embed(const Eigen::SparseMatrix<double>& A, const Pad& pad) {
  ++uses_;
  if (scatter(A)) return M_;
  rebuild(A, nullptr, pad);
  scatter(A);
  return M_;
}

bool PaddedPattern::sum_into(const Eigen::SparseMatrix<double>& H, const Eigen::SparseMatrix<double>& B) {
  const int* mo = M_.outerIndexPtr();
  const int* mi = M_.innerIndexPtr();
  double* mv = M_.valuePtr();
  const int *ho = H.outerIndexPtr(), *hi = H.innerIndexPtr(), *bo = B.outerIndexPtr(), *bi = B.innerIndexPtr();
  const double *hv = H.valuePtr(), *bv = B.valuePtr();
  const Eigen::Index ncols = H.outerSize();
  int outside = 0;
  // Per column: H's and C's sorted entries merged (as Eigen's sum does), then placed on M_'s
  // sorted column, zeros between.
#pragma omp parallel for schedule(static) reduction(+ : outside) if (ncols >= kParallelColumns)
  for (Eigen::Index j = 0; j < ncols; ++j) {
    int p = mo[j];
    const int end = mo[j + 1];
    int a = ho[j], b = bo[j];
    const int ae = ho[j + 1], be = bo[j + 1];
    while (a < ae || b < be) {
      int row;
      double v;
      if (b == be || (a < ae && hi[a] < bi[b])) {
        row = hi[a];
        v = hv[a++] + 0.0;
      } else if (a == ae || bi[b] < hi[a]) {
        row = bi[b];
        v = 0.0 + bv[b++];
      } else {
        row = hi[a];
        v = hv[a++] + bv[b++];
      }
      while (p < end && mi[p] < row) mv[p++] = 0.0;
      if (p == end || mi[p] != row) {
        ++outside;
        break;
      }
      mv[p++] = v;
    }
    while (p < end) mv[p++] = 0.0;
  }
  return outside == 0;
}

Eigen::SparseMatrix<double>& PaddedPattern::embed_sum(const Eigen::SparseMatrix<double>& H,
                                                      const Eigen::SparseMatrix<double>& C, const Pad& pad) {
  ++uses_;
  const Eigen::SparseMatrix<double> Cc = C.isCompressed() ? Eigen::SparseMatrix<double>() : Eigen::SparseMatrix<double>(C);
  const Eigen::SparseMatrix<double>& B = C.isCompressed() ? C : Cc;
  const bool fits = M_.rows() == H.rows() && M_.cols() == H.cols() && C.rows() == H.rows() && C.cols() == H.cols();
  if (fits && sum_into(H, B)) return M_;
  // A coupling outside the kept pattern: the pattern of H + C and the pad, then the sum on it.
  rebuild(H, &B, pad);
  sum_into(H, B);
  return M_;
}

}  // namespace yarnhom::sim
