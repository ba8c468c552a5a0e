#pragma once
// A symmetric sparse matrix assembled straight from dense element blocks, for Newton systems
// whose unknowns come in small groups ("nodes": a yarn vertex's position and the twist angle
// of its edge, 0 to 4 unknowns, consecutive in node order).
//
// Why not triplets: a yarn strip's Hessian gets ~80 entries per contact pair; at 16,000
// unknowns that is 4 million triplets per Newton iteration, and building them and sorting
// them (setFromTriplets) cost more than CHOLMOD's factorization. Here the sparsity pattern
// (the lower triangle in compressed columns) is built once from the list of node pairs that
// elements couple, and kept while that list stays the same; each element then adds its
// blocks in place (one binary search per pair of nodes it touches).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <utility>
#include <vector>

namespace yarnhom::numerics {

class BlockHessian {
 public:
  // node_first[k], node_count[k]: the unknowns of node k (consecutive, in node order).
  BlockHessian(std::vector<int> node_first, std::vector<int> node_count, int ndof);

  int size() const { return ndof_; }
  int node_of(int dof) const { return node_of_dof_[dof]; }

  // The pattern: every pair of nodes (i >= j) that some element couples, diagonal included.
  // Returns true when it differs from the current one (then the matrix is rebuilt, zero).
  bool set_pattern(std::vector<std::pair<int, int>> node_pairs);

  // Values, one array per assembling thread: make `values` the size of the pattern, zero.
  void zero(std::vector<double>& values) const { values.assign(matrix_.nonZeros(), 0.0); }
  // Adds an element's Hessian H (local coordinate k is unknown idx[k], or nothing if < 0)
  // into `values`; every pair of nodes it couples must be in the pattern.
  template <int M>
  void add(const int* idx, const Eigen::Matrix<double, M, M>& H, std::vector<double>& values) const;
  // Sums the threads' values into the matrix (plus `base`'s values, same pattern, if given:
  // a matrix assembled as another one plus a correction).
  void gather(const std::vector<std::vector<double>>& values, const BlockHessian* base = nullptr);

  // The lower triangle (row >= column), compressed.
  const Eigen::SparseMatrix<double>& matrix() const { return matrix_; }

 private:
  int position(int row, int col) const;  // index of (row >= col) in the value array

  std::vector<int> first_, count_, node_of_dof_;
  int ndof_;
  std::vector<std::pair<int, int>> pattern_;
  std::vector<std::vector<int>> col_nodes_;  // per node j: nodes i > j in its columns, sorted
  std::vector<std::vector<int>> col_offset_; // per node j, per entry: rows of earlier nodes
  Eigen::SparseMatrix<double> matrix_;
};

template <int M>
void BlockHessian::add(const int* idx, const Eigen::Matrix<double, M, M>& H, std::vector<double>& values) const {
  for (int i = 0; i < M; ++i) {
    if (idx[i] < 0) continue;
    for (int j = 0; j < M; ++j)
      if (idx[j] >= 0 && idx[i] >= idx[j]) values[position(idx[i], idx[j])] += H(i, j);
  }
}

}  // namespace yarnhom::numerics
