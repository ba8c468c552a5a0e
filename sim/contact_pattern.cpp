#include "sim/contact_pattern.hpp"

#include <algorithm>

namespace yarnhom::sim {

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

Eigen::SparseMatrix<double>& PaddedPattern::embed(const Eigen::SparseMatrix<double>& A, const Pad& pad) {
  ++uses_;
  if (scatter(A)) return M_;
  // Rebuild (A compressed: its outer index is its column starts): A's entries and the pad's full 3x3 blocks (row block fa > column block fb).
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(size_t(A.nonZeros()));
  for (Eigen::Index j = 0; j < A.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it) t.emplace_back(int(it.index()), int(j), 0.0);
  for (const auto& [fa, fb] : pad())
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) t.emplace_back(3 * fa + r, 3 * fb + c, 0.0);
  M_.resize(A.rows(), A.cols());
  M_.setFromTriplets(t.begin(), t.end());
  M_.makeCompressed();
  ++rebuilds_;
  scatter(A);
  return M_;
}

Eigen::SparseMatrix<double>& PaddedPattern::embed_sum(const Eigen::SparseMatrix<double>& H,
                                                      const Eigen::SparseMatrix<double>& C, const Pad& pad) {
  const bool fits = M_.rows() == H.rows() && M_.cols() == H.cols() && C.rows() == H.rows() && C.cols() == H.cols();
  if (fits) {
    const Eigen::SparseMatrix<double> Cc = C.isCompressed() ? Eigen::SparseMatrix<double>() : Eigen::SparseMatrix<double>(C);
    const Eigen::SparseMatrix<double>& B = C.isCompressed() ? C : Cc;
    const int* mo = M_.outerIndexPtr();
    const int* mi = M_.innerIndexPtr();
    double* mv = M_.valuePtr();
    const int *ho = H.outerIndexPtr(), *hi = H.innerIndexPtr(), *bo = B.outerIndexPtr(), *bi = B.innerIndexPtr();
    const double *hv = H.valuePtr(), *bv = B.valuePtr();
    const Eigen::Index ncols = H.outerSize();
    int outside = 0;
    // Per column: H's and C's sorted entries merged (as Eigen's sum does), then placed on M_'s
    // sorted column, zeros between.
#pragma omp parallel for schedule(static) reduction(+ : outside) if (ncols >= 3072)
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
    if (outside == 0) {
      ++uses_;
      return M_;
    }
  }
  Eigen::SparseMatrix<double> sum = H + C;
  sum.makeCompressed();
  return embed(sum, pad);
}

}  // namespace yarnhom::sim
