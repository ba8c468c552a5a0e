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

}  // namespace yarnhom::sim
