#include "yarn/rod/yarn_spacing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace yarnhom::yarn {
namespace {

using V3 = Eigen::Vector3d;

// The segment pairs of a stored pattern over its periodic images: segment a (vertex a to its
// next) in the base tile, segment b in the image at offset o.
struct SegmentPairs {
  const Pattern& p;
  Topology t;
  std::vector<int> idx;                        // vertex's place along its yarn
  std::vector<Eigen::Vector2i> cum, shift;     // offset of a vertex from its yarn's first; per yarn: one turn's
  double edge_max = 0;

  explicit SegmentPairs(const Pattern& pat) : p(pat), t(topology(pat)), idx(pat.size()), cum(pat.size()) {
    for (const auto& yarn : t.yarns) {
      Eigen::Vector2i c = Eigen::Vector2i::Zero();
      for (size_t k = 0; k < yarn.size(); ++k) {
        idx[yarn[k]] = static_cast<int>(k);
        cum[yarn[k]] = c;
        c += t.offset[yarn[k]];
      }
      shift.push_back(c);
    }
    for (int v = 0; v < p.size(); ++v) edge_max = std::max(edge_max, stored_edge(p, t, v).norm());
  }
  V3 at(int v, Eigen::Vector2i o) const { return p.x[v] + V3(o[0] * p.px, o[1] * p.py, 0); }
  // Whether b at image o lies within `skip` edges of a along their yarn (the yarn unwrapped).
  bool near_along(int a, int b, Eigen::Vector2i o, int skip) const {
    const int y = t.yarn_of[a];
    if (t.yarn_of[b] != y) return false;
    const Eigen::Vector2i rel = o - cum[b] + cum[a], s = shift[y];
    const int n = static_cast<int>(t.yarns[y].size());
    const int k = s[0] != 0 ? rel[0] / s[0] : (s[1] != 0 ? rel[1] / s[1] : 0);
    if (rel != k * s) return false;
    int d = idx[b] + k * n - idx[a];
    if (s == Eigen::Vector2i::Zero()) d = std::min(std::abs(d) % n, n - std::abs(d) % n);  // a closed loop
    return std::abs(d) < skip;
  }
  // f(a, b, o, s, u, w): every pair with closest points a0 + s (a1 - a0) and b0 + u (b1 - b0),
  // w from the second to the first, |w| < reach.
  template <class F>
  void each(double reach, int skip, F f) const {
    for (int a = 0; a < p.size(); ++a) {
      const V3 a0 = at(a, {0, 0}), a1 = at(t.next[a], t.offset[a]);
      for (int b = 0; b < p.size(); ++b)
        for (int ox = -2; ox <= 2; ++ox)
          for (int oy = -2; oy <= 2; ++oy) {
            const Eigen::Vector2i o(ox, oy);
            const V3 b0 = at(b, o);
            if ((b0 - a0).norm() > reach + 2 * edge_max) continue;
            if (near_along(a, b, o, skip)) continue;
            const V3 b1 = at(t.next[b], o + t.offset[b]);
            const V3 d1 = a1 - a0, d2 = b1 - b0, r = a0 - b0;
            const double aa = d1.dot(d1), e = d2.dot(d2), c = d1.dot(r), g = d2.dot(r), ab = d1.dot(d2);
            const double den = aa * e - ab * ab;
            double s = den > 1e-12 * aa * e ? std::clamp((ab * g - c * e) / den, 0.0, 1.0) : 0.0;
            double u = (ab * s + g) / e;
            if (u < 0) u = 0, s = std::clamp(-c / aa, 0.0, 1.0);
            else if (u > 1) u = 1, s = std::clamp((ab - c) / aa, 0.0, 1.0);
            const V3 w = (a0 + s * d1) - (b0 + u * d2);
            if (w.norm() < reach) f(a, b, o, s, u, w);
          }
    }
  }
};

}  // namespace

double closest_segment_distance(const Pattern& p, int skip, double reach) {
  const SegmentPairs sp(p);
  double m = std::numeric_limits<double>::infinity();
  sp.each(reach > 0 ? reach : 4 * p.radius, skip,
          [&](int, int, Eigen::Vector2i, double, double, const V3& w) { m = std::min(m, w.norm()); });
  return m;
}

int segment_pairs_closer_than(const Pattern& p, double distance, int skip) {
  const SegmentPairs sp(p);
  int n = 0;
  sp.each(distance, skip, [&](int, int, Eigen::Vector2i, double, double, const V3&) { ++n; });
  return n / 2;  // (a, b, o) and (b, a, -o)
}

void space_yarns(Pattern& p, double distance, double smoothing, int iterations) {
  if (!(distance > 0 && smoothing >= 0 && smoothing < 0.5))
    throw std::invalid_argument("space_yarns: needs a positive distance and a smoothing in [0, 0.5)");
  const int n = p.size();
  for (int it = 0; it < iterations; ++it) {
    const SegmentPairs sp(p);
    std::vector<V3> push(n, V3::Zero());
    std::vector<double> weight(n, 0);
    double closest = distance;
    bool any = false;
    sp.each(distance, 4, [&](int a, int, Eigen::Vector2i, double s, double, const V3& w) {
      const double d = w.norm();
      closest = std::min(closest, d);
      if (d < 1e-12 * p.radius) return;
      any = true;
      // a's share of the shortfall (the pair is met again as (b, a)).
      const V3 m = w / d * (0.5 * (distance - d));
      push[a] += (1 - s) * m, weight[a] += 1 - s;
      push[sp.t.next[a]] += s * m, weight[sp.t.next[a]] += s;
    });
    if (!any) break;
    for (int v = 0; v < n; ++v) push[v] /= std::max(1.0, weight[v]);
    for (int pass = 0; pass < 3; ++pass) {
      std::vector<V3> avg(n);
      for (int v = 0; v < n; ++v) avg[v] = 0.5 * push[v] + 0.25 * (push[sp.t.prev[v]] + push[sp.t.next[v]]);
      push.swap(avg);
    }
    std::vector<V3> move(n);
    double largest = 0;
    for (int v = 0; v < n; ++v) {
      const int a = sp.t.prev[v];
      const V3 ea = stored_edge(p, sp.t, a), eb = stored_edge(p, sp.t, v);
      const V3 mid = 0.5 * ((p.x[v] - ea) + (p.x[v] + eb));
      // The umbrella step moves a vertex by about e^2 kappa / 2: per radius^2 of edge, so that the
      // flow does not depend on the sampling.
      const double lambda = std::min(0.45, smoothing * p.radius * p.radius / (ea.norm() * eb.norm()));
      move[v] = 0.5 * push[v] + lambda * (mid - p.x[v]);
      largest = std::max(largest, move[v].norm());
    }
    const double scale = largest > 0.45 * closest ? 0.45 * closest / largest : 1.0;
    for (int v = 0; v < n; ++v) p.x[v] += scale * move[v];
  }
  // Vertices moved out of the tile go back in by whole periods, their edges' offsets with them.
  for (int v = 0; v < n; ++v) {
    const int kx = static_cast<int>(std::floor(p.x[v][0] / p.px + 0.5));
    const int ky = static_cast<int>(std::floor(p.x[v][1] / p.py + 0.5));
    if (kx == 0 && ky == 0) continue;
    p.x[v] -= V3(kx * p.px, ky * p.py, 0);
    for (auto& e : p.edges) {
      if (e.v0 == v) e.dx -= kx, e.dy -= ky;
      if (e.v1 == v) e.dx += kx, e.dy += ky;
    }
  }
}

}  // namespace yarnhom::yarn
