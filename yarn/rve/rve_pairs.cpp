// The RVE's segment pairs (rve.hpp): which same-yarn pairs never touch, and the candidate
// contact pairs of a configuration, periodic images included.
#include <algorithm>
#include <cmath>
#include <unordered_map>

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
  // box (inflated by reach) touches at most 2 cells per axis.
  auto cell_of = [&](double x) { return static_cast<int64_t>(std::floor(x / cell)); };
  auto key = [](int64_t i, int64_t j, int64_t k) {
    return ((i & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (k & 0x1FFFFF);
  };
  std::unordered_map<int64_t, std::vector<int>> grid;
  grid.reserve(4 * n);
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d lo = base[v].lo.array() - reach, hi = base[v].hi.array() + reach;
    for (int64_t i = cell_of(lo[0]); i <= cell_of(hi[0]); ++i)
      for (int64_t j = cell_of(lo[1]); j <= cell_of(hi[1]); ++j)
        for (int64_t k = cell_of(lo[2]); k <= cell_of(hi[2]); ++k) grid[key(i, j, k)].push_back(v);
  }
  std::vector<Pair> pairs;
  std::vector<int> seen(n, -1);
  int stamp = 0;
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
        ++stamp;
        for (int64_t i = cell_of(bw.lo[0]); i <= cell_of(bw.hi[0]); ++i)
          for (int64_t j = cell_of(bw.lo[1]); j <= cell_of(bw.hi[1]); ++j)
            for (int64_t k = cell_of(bw.lo[2]); k <= cell_of(bw.hi[2]); ++k) {
              auto it = grid.find(key(i, j, k));
              if (it == grid.end()) continue;
              for (int v : it->second) {
                if (seen[v] == stamp) continue;
                seen[v] = stamp;
                // Each unordered pair once: (v, w at o) and (w, v at -o) are the same.
                if (v > w || (v == w && (ox < 0 || (ox == 0 && oy <= 0)))) continue;
                if (excluded(v, w, o)) continue;
                const Box& bv = base[v];
                if (((bv.lo.array() - reach) > bw.hi.array()).any() || ((bv.hi.array() + reach) < bw.lo.array()).any())
                  continue;
                pairs.push_back({v, w, o});
              }
            }
      }
    }
  return pairs;
}

}  // namespace yarnhom::yarn
