// The RVE's segment pairs (rve.hpp): which same-yarn pairs never touch, and the candidate
// contact pairs of a configuration, periodic images included.
#include <algorithm>
#include <cmath>
#include <limits>

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

RveProblem::ImageBound RveProblem::image_bound(const Strain& s, const RveState& st) const {
  // A point's in-plane position is F xi + h n + R u (shell_map.hpp: F the in-plane map of s, n
  // and the columns of R unit vectors), so it lies within |h| + |u| of F xi; the image at offset
  // o has the base tile's reference points moved by F0 (o_x px, o_y py). The segments' far ends
  // across the tile's border are counted as points of the base tile's image.
  ImageBound b;
  const double fa = 1.0 + s[0], fc0 = 1.0 + s[2];
  Eigen::Matrix2d F;
  F << fa, s[1] * fc0, 0.0, fc0 * std::sqrt(1.0 - s[1] * s[1]);
  b.lo = Eigen::Vector2d::Constant(1e300);
  b.hi = Eigen::Vector2d::Constant(-1e300);
  double rho = 0;
  for (int v = 0; v < p_.size(); ++v) {
    const int w = topo_.next[v];
    const Eigen::Vector2d pa = F * (F0_ * Eigen::Vector2d(p_.x[v][0], p_.x[v][1]));
    const Eigen::Vector2d pb =
        F * (F0_ * Eigen::Vector2d(p_.x[w][0] + topo_.offset[v][0] * p_.px, p_.x[w][1] + topo_.offset[v][1] * p_.py));
    b.lo = b.lo.cwiseMin(pa).cwiseMin(pb);
    b.hi = b.hi.cwiseMax(pa).cwiseMax(pb);
    rho = std::max(rho, std::abs(p_.x[v][2]) + st.u[v].norm());
  }
  b.step = F * F0_ * Eigen::Vector2d(p_.px, p_.py).asDiagonal();
  // Round-off of the mapped positions (relative 1e-16) is far below this margin.
  const double scale = b.lo.cwiseAbs().maxCoeff() + b.hi.cwiseAbs().maxCoeff() + rho + 64 * b.step.cwiseAbs().maxCoeff();
  b.pad = rho + 1e-9 * scale;
  // A strain off the map (non-finite points): nothing skipped.
  if (!std::isfinite(scale)) b.pad = std::numeric_limits<double>::infinity();
  return b;
}

void RveProblem::ImageBound::image_box(Eigen::Vector2i o, Eigen::Vector2d& l, Eigen::Vector2d& h) const {
  const Eigen::Vector2d t = step * o.cast<double>();
  l = (lo + t).array() - pad;
  h = (hi + t).array() + pad;
}

bool RveProblem::ImageBound::may_reach(Eigen::Vector2i o, const Eigen::Vector3d& lo3, const Eigen::Vector3d& hi3,
                                       double reach) const {
  Eigen::Vector2d l, h;
  image_box(o, l, h);
  // NaN (a strain off the map) compares false: not skipped.
  return !(((l.array() - reach) > hi3.head<2>().array()).any() || ((h.array() + reach) < lo3.head<2>().array()).any());
}

std::vector<RveProblem::Pair> RveProblem::contact_pairs(const Strain& s, const RveState& st,
                                                        double margin) const {
  const int n = p_.size();
  const double reach = 2.0 * p_.radius + margin;  // centreline distance that may interact
  struct Box {
    Eigen::Vector3d lo, hi;
  };
  // Each image's vertices are mapped once; a segment's far end is the next vertex of the same
  // image unless the yarn leaves the tile there (the same position() values as one call per
  // end: the pairs found do not change).
  std::vector<Eigen::Vector3d> X(n);
  auto image_boxes = [&](Eigen::Vector2i o, std::vector<Box>& boxes) {
    for (int v = 0; v < n; ++v) X[v] = position(s, st, v, o);
    for (int v = 0; v < n; ++v) {
      const Eigen::Vector3d& a = X[v];
      const Eigen::Vector3d b =
          topo_.offset[v].isZero() ? X[topo_.next[v]] : position(s, st, topo_.next[v], o + topo_.offset[v]);
      boxes[v] = Box{a.cwiseMin(b), a.cwiseMax(b)};
    }
  };
  std::vector<Box> base(n);
  image_boxes(Eigen::Vector2i::Zero(), base);
  Box all{Eigen::Vector3d::Constant(1e300), Eigen::Vector3d::Constant(-1e300)};
  double cell = reach;
  for (int v = 0; v < n; ++v) {
    all.lo = all.lo.cwiseMin(base[v].lo);
    all.hi = all.hi.cwiseMax(base[v].hi);
    cell = std::max(cell, (base[v].hi - base[v].lo).maxCoeff() + reach);
  }
  // An image whose in-plane box (image_bound: from the map alone) misses the base tile's by more
  // than reach is skipped unmapped; the exact test below would have skipped it too (the bound
  // holds the exact box), so the pairs are the same.
  const ImageBound bound = image_bound(s, st);
  // Hash grid of the base tile's segments, cells at least one segment + reach wide, so each
  // box (inflated by reach) touches at most 2 cells per axis (numerics/hash_grid.hpp).
  numerics::SpatialHash grid(cell, size_t(n));
  for (int v = 0; v < n; ++v) grid.insert(v, base[v].lo.array() - reach, base[v].hi.array() + reach);
  std::vector<Pair> pairs;
  std::vector<Box> boxes(n);
  const int K = 2;  // images up to two tiles away (a small tile under compression)
  for (int ox = -K; ox <= K; ++ox)
    for (int oy = -K; oy <= K; ++oy) {
      const Eigen::Vector2i o(ox, oy);
      if (!bound.may_reach(o, all.lo, all.hi, reach)) continue;
      // Cheap rejection of a whole image: its vertex bounding box against the base tile's.
      Box img{Eigen::Vector3d::Constant(1e300), Eigen::Vector3d::Constant(-1e300)};
      if (o.isZero()) boxes = base;
      else image_boxes(o, boxes);
      for (int w = 0; w < n; ++w) {
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
          const Box& bv = base[v];
          if (((bv.lo.array() - reach) > bw.hi.array()).any() || ((bv.hi.array() + reach) < bw.lo.array()).any())
            return;
          if (excluded(v, w, o)) return;
          pairs.push_back({v, w, o});
        });
      }
    }
  return pairs;
}

}  // namespace yarnhom::yarn
