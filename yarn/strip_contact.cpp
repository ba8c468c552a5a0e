#include "yarn/strip_contact.hpp"

#include <algorithm>
#include <cmath>

namespace yarnhom::yarn {

double StripContact::energy(const Vec12& q, double La, double Lb, Vec12* g, Mat12* H) const {
  return segment_contact_energy(q, La, Lb, params_, g, H);
}

double StripContact::step_bound(const Vec12& q, const Vec12& dq) const {
  const double ma = std::max(dq.segment<3>(0).norm(), dq.segment<3>(3).norm());
  const double mb = std::max(dq.segment<3>(6).norm(), dq.segment<3>(9).norm());
  if (ma + mb <= 0) return 1.0;
  return std::min(1.0, 0.9 * segment_distance(q) / (ma + mb));
}

double segment_distance(const Vec12& q) {
  // Minimize |a0 + s u - b0 - t v| over s, t in [0, 1]: the unconstrained stationary point
  // clamped to the square, then each clamped parameter re-optimized given the other (the
  // minimum of a convex quadratic over a square lies on the clamped line of one of them).
  const Eigen::Vector3d a0 = q.segment<3>(0), b0 = q.segment<3>(6);
  const Eigen::Vector3d u = q.segment<3>(3) - a0, v = q.segment<3>(9) - b0, w = a0 - b0;
  const double a = u.dot(u), b = u.dot(v), c = v.dot(v), d = u.dot(w), e = v.dot(w);
  auto clamp01 = [](double x) { return std::min(1.0, std::max(0.0, x)); };
  const double den = a * c - b * b;
  double s = 0, t = 0;
  if (a <= 0 && c <= 0) return w.norm();
  if (a <= 0) {
    t = clamp01(e / c);
  } else if (c <= 0) {
    s = clamp01(-d / a);
  } else {
    s = den > 1e-14 * a * c ? clamp01((b * e - c * d) / den) : 0.0;  // parallel: any s
    t = (b * s + e) / c;
    if (t < 0 || t > 1) {
      t = clamp01(t);
      s = clamp01((b * t - d) / a);
    }
  }
  return (w + s * u - t * v).norm();
}

}  // namespace yarnhom::yarn
