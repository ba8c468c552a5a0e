#include "numerics/block_hessian.hpp"

#include <algorithm>
#include <stdexcept>

namespace yarnhom::numerics {

BlockHessian::BlockHessian(std::vector<int> node_first, std::vector<int> node_count, int ndof)
    : first_(std::move(node_first)), count_(std::move(node_count)), ndof_(ndof) {
  if (first_.size() != count_.size()) throw std::invalid_argument("BlockHessian: one first dof and count per node");
  node_of_dof_.assign(ndof_, -1);
  for (size_t k = 0; k < first_.size(); ++k)
    for (int c = 0; c < count_[k]; ++c) node_of_dof_[first_[k] + c] = static_cast<int>(k);
  for (int d = 0; d < ndof_; ++d)
    if (node_of_dof_[d] < 0) throw std::invalid_argument("BlockHessian: a dof belongs to no node");
  matrix_.resize(ndof_, ndof_);
}

bool BlockHessian::set_pattern(std::vector<std::pair<int, int>> pairs) {
  // Nodes without unknowns contribute nothing; every node with some gets its diagonal block.
  pairs.erase(std::remove_if(pairs.begin(), pairs.end(),
                             [&](const auto& p) { return count_[p.first] == 0 || count_[p.second] == 0; }),
              pairs.end());
  for (size_t k = 0; k < count_.size(); ++k)
    if (count_[k] > 0) pairs.emplace_back(int(k), int(k));
  for (auto& p : pairs)
    if (p.first < p.second) std::swap(p.first, p.second);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  if (pairs == pattern_ && matrix_.isCompressed() && matrix_.nonZeros() > 0) return false;
  pattern_ = std::move(pairs);

  const int nn = static_cast<int>(count_.size());
  col_nodes_.assign(nn, {});
  col_offset_.assign(nn, {});
  for (const auto& [i, j] : pattern_)
    if (i != j) col_nodes_[j].push_back(i);
  std::vector<int> below(nn, 0);  // rows of other nodes in each column of node j
  for (int j = 0; j < nn; ++j) {
    auto& v = col_nodes_[j];
    std::sort(v.begin(), v.end());
    int off = 0;
    for (int i : v) {
      col_offset_[j].push_back(off);
      off += count_[i];
    }
    below[j] = off;
  }
  // Compressed columns: column (j, b) holds rows b.. of node j, then the other nodes' rows.
  std::vector<int> outer(ndof_ + 1, 0);
  for (int j = 0; j < nn; ++j)
    for (int b = 0; b < count_[j]; ++b) outer[first_[j] + b + 1] = (count_[j] - b) + below[j];
  for (int c = 0; c < ndof_; ++c) outer[c + 1] += outer[c];
  const int nnz = outer[ndof_];
  matrix_ = Eigen::SparseMatrix<double>(ndof_, ndof_);
  matrix_.resizeNonZeros(nnz);
  std::copy(outer.begin(), outer.end(), matrix_.outerIndexPtr());
  int* inner = matrix_.innerIndexPtr();
  for (int j = 0; j < nn; ++j)
    for (int b = 0; b < count_[j]; ++b) {
      int p = outer[first_[j] + b];
      for (int a = b; a < count_[j]; ++a) inner[p++] = first_[j] + a;
      for (int i : col_nodes_[j])
        for (int a = 0; a < count_[i]; ++a) inner[p++] = first_[i] + a;
    }
  std::fill(matrix_.valuePtr(), matrix_.valuePtr() + nnz, 0.0);
  return true;
}

int BlockHessian::position(int row, int col) const {
  const int A = node_of_dof_[row], B = node_of_dof_[col];
  const int a = row - first_[A], b = col - first_[B];
  const int base = matrix_.outerIndexPtr()[col];
  if (A == B) return base + (a - b);
  const auto& v = col_nodes_[B];
  const auto it = std::lower_bound(v.begin(), v.end(), A);
  if (it == v.end() || *it != A) throw std::logic_error("BlockHessian: an element couples nodes outside the pattern");
  return base + (count_[B] - b) + col_offset_[B][it - v.begin()] + a;
}

void BlockHessian::gather(const std::vector<std::vector<double>>& values, const BlockHessian* base) {
  double* out = matrix_.valuePtr();
  const int nnz = static_cast<int>(matrix_.nonZeros());
  if (base && base->matrix_.nonZeros() != nnz) throw std::logic_error("BlockHessian: gather onto a different pattern");
  if (base) std::copy(base->matrix_.valuePtr(), base->matrix_.valuePtr() + nnz, out);
  else std::fill(out, out + nnz, 0.0);
  for (const auto& v : values)
    for (int k = 0; k < nnz; ++k) out[k] += v[k];
}

}  // namespace yarnhom::numerics
