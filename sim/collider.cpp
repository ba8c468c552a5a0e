#include "sim/collider.hpp"

#include <cmath>

namespace yarnhom::sim {

double collider_distance(const Collider& c, const Eigen::Vector3d& x, Eigen::Vector3d* grad, Eigen::Matrix3d* hess) {
  if (c.kind == Collider::Kind::Plane) {
    if (grad) *grad = c.normal;
    if (hess) hess->setZero();
    return c.normal.dot(x - c.center);
  }
  const Eigen::Vector3d r = x - c.center;
  const double n = r.norm();
  const Eigen::Vector3d rh = r / n;
  if (grad) *grad = rh;
  if (hess) *hess = (Eigen::Matrix3d::Identity() - rh * rh.transpose()) / n;
  return n - c.radius;
}

double collider_time_of_impact(const Collider& c, const Eigen::Vector3d& x, const Eigen::Vector3d& p) {
  if (c.kind == Collider::Kind::Plane) {
    const double d = c.normal.dot(x - c.center), v = c.normal.dot(p);
    if (v >= 0) return 1.0;  // moving away or parallel
    return std::min(1.0, d / -v);
  }
  // |r + t p|^2 = R^2: a t^2 + 2 b t + k = 0 with k = |r|^2 - R^2 > 0 outside.
  const Eigen::Vector3d r = x - c.center;
  const double a = p.squaredNorm(), b = r.dot(p), k = r.squaredNorm() - c.radius * c.radius;
  if (a == 0 || b >= 0) return 1.0;
  const double disc = b * b - a * k;
  if (disc < 0) return 1.0;
  // Smaller root, written to avoid cancellation: t = k / (-b + sqrt(disc)).
  const double t = k / (-b + std::sqrt(disc));
  return std::min(1.0, std::max(0.0, t));
}

}  // namespace yarnhom::sim
