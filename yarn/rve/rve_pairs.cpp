// The RVE's segment pairs (rve.hpp): which same-yarn pairs never touch, and the candidate
// contact pairs of a configuration, periodic images included.
#include <algorithm>
#include <cmath>

#include "numerics/hash_grid.hpp"
#include "yarn/rve/rve.hpp"

namespace yarnhom::yarn {

uint64_t RveProblem::pair_key(int a, int b, Eigen::Vector2i o) {
  if (a > b || (a == b && (o[0] < 0 || (o[0] == 0 && o[1] < 0)))) {
    std::swap(a, b);
    o = -o;
  }
  return (uint64_t(a) << 40) | (uint64_t(b) << 16) | (uint64_t(o[0] + 128) << 8) | uint64_t(o[1] + 128);
}

bool RveProblem::excluded(int a, int b, Eigen::Vector2i o) const {
  return (a == b && o.isZero()) || excluded_.count(pair_key(a, b, o)) > 0;
}

std::vector<RveProblem::Pair> RveProblem::contact_pairs(const Strain& s, const RveState& st,
                                                        double margin) const {
  const int n = p_.size();
  const double reach = 2.0 * p_.radius + margin;  // centreline distance that may interact
  struct Box {
    Eigen::Vector3d lo, hi;
  };
  auto seg_box = [&](int v, Eigen::Vector2i o) {
    const Eigen::Vector3d a = position(s, st, v, o), b = position(s, st, topo_.next[v], o + topo_.offset[v]);
    return Box{a.cwiseMin(b), a.cwiseMax(b)};
  };
  std::vector<Box> base(n);
  Box all{Eigen::Vector3d::Constant(1e300), Eigen::Vector3d::Constant(-1e300)};
  double cell = reach;
  for (int v = 0; v < n; ++v) {
    base[v] = seg_box(v, Eigen::Vector2i::Zero());
    all.lo = all.lo.cwiseMin(base[v].lo);
    all.hi = all.hi.cwiseMax(base[v].hi);
    cell = std::max(cell, (base[v].hi - base[v].lo).maxCoeff() + reach);
  }
  // Hash grid of the base tile's segments, cells at least one segment + reach wide, so each
  // box (inflated by reach) touches at most 2 cells per axis (numerics/hash_grid.hpp).
  numerics::SpatialHash grid(cell, size_t(n));
  for (int v = 0; v < n; ++v) grid.insert(v, base[v].lo.array() - reach, base[v].hi.array() + reach);
  std::vector<Pair> pairs;
  const int K = 2;  // images up to two tiles away (a small tile under compression)
  for (int ox = -K; ox <= K; ++ox)
    for (int oy = -K; oy <= K; ++oy) {
      const Eigen::Vector2i o(ox, oy);
      // Cheap rejection of a whole image: its vertex bounding box against the base tile's.
      Box img{Eigen::Vector3d::Constant(1e300), Eigen::Vector3d::Constant(-1e300)};
      std::vector<Box> boxes(n);
      for (int w = 0; w < n; ++w) {
        boxes[w] = seg_box(w, o);
        img.lo = img.lo.cwiseMin(boxes[w].lo);
        img.hi = img.hi.cwiseMax(boxes[w].hi);
      }
      if (((img.lo.array() - reach) > all.hi.array()).any() || ((img.hi.array() + reach) < all.lo.array()).any())
        continue;
      for (int w = 0; w < n; ++w) {
        const Box& bw = boxes[w];
        grid.query(bw.lo, bw.hi, [&](int v) {
          // Each unordered pair once: (v, w at o) and (w, v at -o) are the same.
          if (v > w || (v == w && (ox < 0 || (ox == 0 && oy <= 0)))) return;
          if (excluded(v, w, o)) return;
          const Box& bv = base[v];
          if (((bv.lo.array() - reach) > bw.hi.array()).any() || ((bv.hi.array() + reach) < bw.lo.array()).any())
            return;
          pairs.push_back({v, w, o});
        });
      }
    }
  return pairs;
}

}  // namespace yarnhom::yarn
