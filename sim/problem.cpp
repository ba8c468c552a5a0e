#include "sim/problem.hpp"

#include "sim/shell_energy.hpp"

namespace yarnhom::sim {

Problem make_problem(Mesh mesh, MaterialFn material, double areal_density) {
  Problem p;
  p.rest = make_element_rests(mesh);
  p.vertex_area = vertex_areas(mesh);
  p.mass = areal_density * p.vertex_area;
  p.areal_density = areal_density;
  p.mesh = std::move(mesh);
  p.material = std::move(material);
  return p;
}

Eigen::VectorXd flatten(const Eigen::MatrixX3d& x) {
  Eigen::VectorXd v(3 * x.rows());
  for (int i = 0; i < x.rows(); ++i) v.segment<3>(3 * i) = x.row(i).transpose();
  return v;
}

Eigen::MatrixX3d unflatten(const Eigen::VectorXd& v) {
  Eigen::MatrixX3d x(v.size() / 3, 3);
  for (int i = 0; i < x.rows(); ++i) x.row(i) = v.segment<3>(3 * i).transpose();
  return x;
}

}  // namespace yarnhom::sim
