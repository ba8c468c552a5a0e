#include "yarn/ccd.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace yarnhom::yarn {

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
  // Safe throughout when even the fastest approach cannot close the gap.
  if (res.d0 - l > dmin) return res;
  const double stop = opt.tolerance * (res.d0 - dmin);
  double t = 0, d = res.d0;
  for (int it = 0; it < opt.max_iterations; ++it) {
    const double dt = (d - dmin) / l;  // [t, t + dt] is safe
    if (t + dt >= 1.0) {
      res.t = 1.0;
      return res;
    }
    t += dt;
    d = dist(t);
    if (d - dmin <= stop) break;  // reached d_min (to the tolerance): a contact at t
  }
  res.t = t;
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
  auto cell_of = [&](double x) { return static_cast<int64_t>(std::floor(x / cell)); };
  auto key = [](int64_t i, int64_t j, int64_t k) {
    return ((i & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (k & 0x1FFFFF);
  };
  std::unordered_map<int64_t, std::vector<int>> grid;
  grid.reserve(4 * a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector3d lo = ba[i].lo.array() - reach, hi = ba[i].hi.array() + reach;
    for (int64_t x = cell_of(lo[0]); x <= cell_of(hi[0]); ++x)
      for (int64_t y = cell_of(lo[1]); y <= cell_of(hi[1]); ++y)
        for (int64_t z = cell_of(lo[2]); z <= cell_of(hi[2]); ++z) grid[key(x, y, z)].push_back(static_cast<int>(i));
  }
  std::vector<int> seen(a.size(), -1);
  for (size_t j = 0; j < b.size(); ++j) {
    const Box bb = box(b[j]);
    for (int64_t x = cell_of(bb.lo[0]); x <= cell_of(bb.hi[0]); ++x)
      for (int64_t y = cell_of(bb.lo[1]); y <= cell_of(bb.hi[1]); ++y)
        for (int64_t z = cell_of(bb.lo[2]); z <= cell_of(bb.hi[2]); ++z) {
          auto it = grid.find(key(x, y, z));
          if (it == grid.end()) continue;
          for (int i : it->second) {
            if (seen[i] == static_cast<int>(j)) continue;
            seen[i] = static_cast<int>(j);
            if (((ba[i].lo.array() - reach) > bb.hi.array()).any() || ((ba[i].hi.array() + reach) < bb.lo.array()).any())
              continue;
            out.emplace_back(i, static_cast<int>(j));
          }
        }
  }
  return out;
}

}  // namespace yarnhom::yarn
