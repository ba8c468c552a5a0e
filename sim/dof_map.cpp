#include "sim/dof_map.hpp"

#include <stdexcept>
#include <string>

namespace yarnhom::sim {

DofMap make_dof_map(int num_vertices, const std::vector<int>& prescribed) {
  DofMap d;
  d.free_index.assign(num_vertices, 0);
  for (int v : prescribed) {
    if (v < 0 || v >= num_vertices)
      throw std::invalid_argument("prescribed vertex " + std::to_string(v) + " out of range (mesh has " +
                                  std::to_string(num_vertices) + ")");
    d.free_index[v] = -1;
  }
  for (int v = 0; v < num_vertices; ++v)
    if (d.free_index[v] == 0) {
      d.free_index[v] = int(d.free_vertices.size());
      d.free_vertices.push_back(v);
    }
  return d;
}

Eigen::VectorXd gather_free(const DofMap& d, const Eigen::VectorXd& x) {
  Eigen::VectorXd xf(3 * d.num_free());
  for (int i = 0; i < d.num_free(); ++i) xf.segment<3>(3 * i) = x.segment<3>(3 * d.free_vertices[i]);
  return xf;
}

void scatter_free(const DofMap& d, const Eigen::VectorXd& xf, Eigen::VectorXd& x) {
  for (int i = 0; i < d.num_free(); ++i) x.segment<3>(3 * d.free_vertices[i]) = xf.segment<3>(3 * i);
}

}  // namespace yarnhom::sim
