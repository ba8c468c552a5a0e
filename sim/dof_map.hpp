#pragma once
// Which vertices move freely and which are prescribed (pins and handles). Prescribed vertices
// are eliminated from the Newton system: their positions are set, never solved for, and the
// force the rest of the cloth exerts on them is their reaction (clamp force).
#include <Eigen/Core>
#include <vector>

namespace yarnhom::sim {

struct DofMap {
  std::vector<int> free_index;  // per vertex: index among the free vertices, or -1 if prescribed
  std::vector<int> free_vertices;
  int num_free() const { return int(free_vertices.size()); }
};

DofMap make_dof_map(int num_vertices, const std::vector<int>& prescribed);

// x (3n, vertex-major) restricted to the free vertices, and back (prescribed entries kept).
Eigen::VectorXd gather_free(const DofMap& d, const Eigen::VectorXd& x);
void scatter_free(const DofMap& d, const Eigen::VectorXd& xf, Eigen::VectorXd& x);

}  // namespace yarnhom::sim
