#include "sim/handles.hpp"

#include <algorithm>

namespace yarnhom::sim {

Eigen::Vector3d handle_offset(const Handle& h, double t) {
  if (h.path.empty()) return Eigen::Vector3d::Zero();
  auto at = [&](size_t k) { return Eigen::Vector3d(h.path[k][1], h.path[k][2], h.path[k][3]); };
  if (t <= h.path.front()[0]) return at(0);
  if (t >= h.path.back()[0]) return at(h.path.size() - 1);
  size_t k = 1;
  while (h.path[k][0] < t) ++k;
  const double t0 = h.path[k - 1][0], t1 = h.path[k][0];
  const double w = t1 > t0 ? (t - t0) / (t1 - t0) : 1.0;
  return (1 - w) * at(k - 1) + w * at(k);
}

std::vector<int> prescribed_vertices(const std::vector<Handle>& handles) {
  std::vector<int> v;
  for (const Handle& h : handles) v.insert(v.end(), h.vertices.begin(), h.vertices.end());
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

Eigen::VectorXd handle_targets(const std::vector<Handle>& handles, const Eigen::VectorXd& x0, double t) {
  Eigen::VectorXd x = x0;
  for (const Handle& h : handles) {
    const Eigen::Vector3d d = handle_offset(h, t);
    for (int v : h.vertices) x.segment<3>(3 * v) = x0.segment<3>(3 * v) + d;
  }
  return x;
}

}  // namespace yarnhom::sim
