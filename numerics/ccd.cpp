#include "numerics/ccd.hpp"

#include <algorithm>
#include <cmath>

#include "numerics/hash_grid.hpp"

namespace yarnhom::numerics {

CcdResult segment_ccd(const Vec12& q0, const Vec12& q1, double dmin, const CcdOptions& opt) {
  CcdResult res;
  auto dist = [&](double t) {
    const Vec12 q = q0 + t * (q1 - q0);
    ++res.iterations;
    return segment_distance(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
  };
  res.d0 = dist(0.0);
  if (!(res.d0 > dmin)) {
    res.t = 0;
    return res;
  }
  const Vec12 dq = q1 - q0;
  const Eigen::Vector3d m = 0.25 * (dq.segment<3>(0) + dq.segment<3>(3) + dq.segment<3>(6) + dq.segment<3>(9));
  const double l = std::max((dq.segment<3>(0) - m).norm(), (dq.segment<3>(3) - m).norm()) +
                   std::max((dq.segment<3>(6) - m).norm(), (dq.segment<3>(9) - m).norm());
  advance(dist, dmin, l, opt, res);
  return res;
}

std::vector<std::pair<int, int>> swept_pairs(const std::vector<SegmentMove>& a, const std::vector<SegmentMove>& b,
                                             double reach) {
  struct Box {
    Eigen::Vector3d lo, hi;
  };
  auto box = [](const SegmentMove& m) {
    Box bx{m.start[0], m.start[0]};
    for (const Eigen::Vector3d& p : {m.start[1], m.end[0], m.end[1]}) {
      bx.lo = bx.lo.cwiseMin(p);
      bx.hi = bx.hi.cwiseMax(p);
    }
    return bx;
  };
  std::vector<std::pair<int, int>> out;
  if (a.empty() || b.empty()) return out;
  std::vector<Box> ba(a.size());
  double cell = reach;
  for (size_t i = 0; i < a.size(); ++i) {
    ba[i] = box(a[i]);
    cell = std::max(cell, (ba[i].hi - ba[i].lo).maxCoeff() + reach);
  }
  // Cells at least one (inflated) box wide: each box touches at most 2 cells per axis.
  SpatialHash grid(cell, a.size());
  for (size_t i = 0; i < a.size(); ++i)
    grid.insert(static_cast<int>(i), ba[i].lo.array() - reach, ba[i].hi.array() + reach);
  for (size_t j = 0; j < b.size(); ++j) {
    const Box bb = box(b[j]);
    grid.query(bb.lo, bb.hi, [&](int i) {
      if (((ba[i].lo.array() - reach) > bb.hi.array()).any() || ((ba[i].hi.array() + reach) < bb.lo.array()).any())
        return;
      out.emplace_back(i, static_cast<int>(j));
    });
  }
  return out;
}

}  // namespace yarnhom::numerics
