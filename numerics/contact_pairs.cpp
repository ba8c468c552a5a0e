#include "numerics/contact_pairs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace yarnhom::numerics {

double contact_barrier_energy(ContactKind kind, const Vec12& q, const BarrierParams& p, Vec12* g, Mat12* H) {
  const double Dmin = p.dmin * p.dmin, span = p.dhat * p.dhat - Dmin;
  const double D0 = contact_distance_squared(kind, q);
  if (D0 >= p.dhat * p.dhat) {
    if (g) g->setZero();
    if (H) H->setZero();
    return 0.0;
  }
  if (!g && !H) return p.kappa * barrier((D0 - Dmin) / span);
  Vec12 gD;
  Mat12 HD;
  const double D = contact_distance_squared(kind, q, &gD, H ? &HD : nullptr);
  double b1, b2;
  const double b = barrier((D - Dmin) / span, &b1, &b2);
  if (!std::isfinite(b)) {
    if (g) g->setConstant(std::numeric_limits<double>::quiet_NaN());
    if (H) H->setConstant(std::numeric_limits<double>::quiet_NaN());
    return b;
  }
  if (g) *g = (p.kappa * b1 / span) * gD;
  if (H) *H = (p.kappa * b2 / (span * span)) * (gD * gD.transpose()) + (p.kappa * b1 / span) * HD;
  return p.kappa * b;
}

double contact_speed(ContactKind kind, const Vec12& dq) {
  const Eigen::Vector3d m = 0.25 * (dq.segment<3>(0) + dq.segment<3>(3) + dq.segment<3>(6) + dq.segment<3>(9));
  if (kind == ContactKind::PointTriangle)
    return (dq.segment<3>(0) - m).norm() +
           std::max({(dq.segment<3>(3) - m).norm(), (dq.segment<3>(6) - m).norm(), (dq.segment<3>(9) - m).norm()});
  return std::max((dq.segment<3>(0) - m).norm(), (dq.segment<3>(3) - m).norm()) +
         std::max((dq.segment<3>(6) - m).norm(), (dq.segment<3>(9) - m).norm());
}

CcdResult contact_ccd(ContactKind kind, const Vec12& q0, const Vec12& q1, double dmin, double eta,
                      const CcdOptions& opt) {
  CcdResult res;
  auto dist = [&](double t) {
    ++res.iterations;
    return contact_distance(kind, q0 + t * (q1 - q0));
  };
  res.d0 = dist(0.0);
  if (!(res.d0 > dmin)) {
    res.t = 0;
    return res;
  }
  const double l = contact_speed(kind, q1 - q0);
  advance(dist, dmin + eta * (res.d0 - dmin), l, opt, res);  // never closer than that on [0, t]
  return res;
}

}  // namespace yarnhom::numerics
