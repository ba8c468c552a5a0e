#pragma once
// The sparsity pattern of the Newton matrix over the free vertices, built once per mesh and
// set of prescribed vertices, and the slots into which element and vertex blocks are added.
//
// Only the lower triangle is stored (column-major, what Eigen's SimplicialLDLT and CHOLMOD
// read). Every free vertex owns three consecutive unknowns, so the rows of one 3x3 block in a
// column are contiguous in the value array: a block is located by the position of its first
// row in each of its three columns.
#include <Eigen/Sparse>
#include <array>
#include <memory>
#include <vector>

#include "sim/dof_map.hpp"
#include "sim/mesh.hpp"

namespace yarnhom::sim {

class PaddedPattern;  // sim/contact_pattern.hpp
struct ElementChunks;  // sim/shell_energy.cpp

struct HessianPattern {
  Eigen::SparseMatrix<double> matrix;  // 3F x 3F, lower triangle, values 0
  // Per element, per pair (a, b) of its 6 vertex slots (x0, x1, x2, f0, f1, f2) with a's free
  // index >= b's, per column component c: value index of entry (3 fa + (c if a == b else 0),
  // 3 fb + c) -- the first stored row of that column of the block; -1 when either vertex is
  // prescribed or missing, or the pair is stored as (b, a).
  std::vector<int> elem_slots;  // [m][6][6][3]
  std::vector<unsigned long long> same_vertex;  // [m]: bit 6a + b when slots a and b are one vertex
  std::vector<int> diag_slots;  // [F][3]: value index of (3f + c, 3f + c)
  // The matrix's kept pattern with contact couplings (sim/contact_pattern.hpp), across steps;
  // null: the matrix with contact goes to the solver on its own pattern (the simulator sets it
  // with self-collision on).
  std::shared_ptr<PaddedPattern> contact;
  // The element loop's chunks and their arenas (sim/shell_energy.cpp), laid out at the first
  // evaluation with this pattern and kept.
  mutable std::shared_ptr<ElementChunks> chunks;
  int slot(int t, int a, int b, int c) const { return elem_slots[((size_t(t) * 6 + a) * 6 + b) * 3 + c]; }
};

HessianPattern make_hessian_pattern(const Mesh& mesh, const DofMap& dofs);

// Adds the lower triangle of the element Hessian (18 x 18 in the element's slot order) to the
// value array.
void add_element_hessian(const HessianPattern& p, int t, const Eigen::Matrix<double, 18, 18>& H, double* values);

// dst: src's pattern (compressed), every value 0; the copy on the OpenMP threads.
void copy_pattern(const Eigen::SparseMatrix<double>& src, Eigen::SparseMatrix<double>& dst);
// Every stored value of A set to v, on the OpenMP threads.
void fill_values(Eigen::SparseMatrix<double>& A, double v);

// Adds a symmetric 3x3 block to a free vertex's diagonal block.
void add_vertex_hessian(const HessianPattern& p, int free_vertex, const Eigen::Matrix3d& H, double* values);

}  // namespace yarnhom::sim
