#include "sim/element_rest.hpp"

#include <Eigen/Dense>

namespace yarnhom::sim {

ElementRest element_rest(const Eigen::Vector2d& u0, const Eigen::Vector2d& u1, const Eigen::Vector2d& u2) {
  Eigen::Matrix2d Dm;
  Dm << u1 - u0, u2 - u0;
  ElementRest r;
  r.area = 0.5 * Dm.determinant();
  r.Binv = Dm.inverse();
  const Eigen::Vector2d eps[3] = {{0, -1}, {1, 1}, {-1, 0}};
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector2d b = r.Binv.transpose() * eps[i];
    r.Q.col(i) << b.x() * b.x(), b.x() * b.y(), b.y() * b.y();
  }
  return r;
}

}  // namespace yarnhom::sim
