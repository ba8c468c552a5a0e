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

std::vector<std::pair<int, int>> box_pairs(const std::vector<Box3>& a, const std::vector<Box3>& b, bool same) {
  std::vector<std::pair<int, int>> out;
  if (a.empty() || b.empty()) return out;
  // Cells at least as large as the larger boxes (the 90th percentile's double, so one long box
  // does not coarsen the grid for all): a box then touches few cells.
  std::vector<double> ext;
  ext.reserve(a.size());
  for (const Box3& x : a) ext.push_back((x.hi - x.lo).maxCoeff());
  const size_t k = std::min(ext.size() - 1, ext.size() * 9 / 10);
  std::nth_element(ext.begin(), ext.begin() + k, ext.end());
  double cell = std::max(2 * ext[k], 1e-9);
  // ... and no box spans more than 8 cells per axis.
  for (const Box3& x : a) cell = std::max(cell, (x.hi - x.lo).maxCoeff() / 8);
  for (const Box3& x : b) cell = std::max(cell, (x.hi - x.lo).maxCoeff() / 8);
  SpatialHash grid(cell, a.size());
  for (size_t i = 0; i < a.size(); ++i) grid.insert(int(i), a[i].lo, a[i].hi);
  // (same: only i < j, by the hash's sorted cells: half the scan, the same pairs in the same order)
  for (size_t j = 0; j < b.size(); ++j)
    grid.query(
        b[j].lo, b[j].hi,
        [&](int i) {
          if (a[i].overlaps(b[j])) out.emplace_back(i, int(j));
        },
        same ? int(j) : INT32_MAX);
  return out;
}

}  // namespace yarnhom::numerics
