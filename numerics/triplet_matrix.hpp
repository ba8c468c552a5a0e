#pragma once
// A compressed column-major sparse matrix from triplets: the matrix Eigen's setFromTriplets
// makes, bit for bit (duplicate entries summed in the triplets' order, each column's rows
// sorted), built on the OpenMP threads. The simulator's contact and seam terms hand over 10^5
// and more triplets a step; setFromTriplets is serial.
//
// The triplets' (column, row) keys sorted stably by a radix sort (numerics/radix_sort.hpp), the
// sorted list cut into runs of one key, each run summed from its first triplet on.
#include <Eigen/Sparse>
#include <vector>

namespace yarnhom::numerics {

void triplets_to_matrix(const std::vector<Eigen::Triplet<double>>& triplets, Eigen::Index rows, Eigen::Index cols,
                        Eigen::SparseMatrix<double>& out);

}  // namespace yarnhom::numerics
