#include "yarn/rve/rve_ccd.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "numerics/ccd.hpp"

namespace yarnhom::yarn {

using numerics::segment_distance;
using numerics::CcdResult;
using numerics::segment_ccd;
using numerics::SegmentMove;
using numerics::pair_move;
using numerics::V3;

namespace {

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  void add(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bool near(const Box& o, double reach) const {
    return !(((lo.array() - reach) > o.hi.array()).any() || ((hi.array() + reach) < o.lo.array()).any());
  }
};

// Vertex positions of one image in the two configurations of a move. At one strain (a Newton
// step) the map is evaluated once per vertex for both.
void image_points(const RveProblem& rve, const Strain& s0, const RveState& st0, const Strain& s1, const RveState& st1,
                  Eigen::Vector2i o, int v, Eigen::Vector3d& x0, Eigen::Vector3d& x1) {
  const ShellPoint<double> a = rve.shell_point(s0, v, o);
  const V3<double> p0 = a.apply(st0.u[v]);
  x0 = Eigen::Vector3d(p0.x, p0.y, p0.z);
  const ShellPoint<double> b = s1 == s0 ? a : rve.shell_point(s1, v, o);
  const V3<double> p1 = b.apply(st1.u[v]);
  x1 = Eigen::Vector3d(p1.x, p1.y, p1.z);
}

// The segments of the image at offset o, moving from configuration 0 to configuration 1
// (segment v: vertex v to next(v), which lies in the image o + offset(v)), and their joint
// swept box.
std::vector<SegmentMove> image_moves(const RveProblem& rve, const Strain& s0, const RveState& st0, const Strain& s1,
                                     const RveState& st1, Eigen::Vector2i o, Box& box) {
  const Topology& t = rve.topo();
  const int n = rve.pattern().size();
  std::vector<Eigen::Vector3d> x0(n), x1(n);
  for (int v = 0; v < n; ++v) {
    image_points(rve, s0, st0, s1, st1, o, v, x0[v], x1[v]);
    box.add(x0[v]);
    box.add(x1[v]);
  }
  std::vector<SegmentMove> m(n);
  for (int v = 0; v < n; ++v) {
    const int w = t.next[v];
    m[v].start[0] = x0[v];
    m[v].end[0] = x1[v];
    if (t.offset[v].isZero()) {
      m[v].start[1] = x0[w];
      m[v].end[1] = x1[w];
    } else {  // the segment crosses into the neighbouring image
      image_points(rve, s0, st0, s1, st1, o + t.offset[v], w, m[v].start[1], m[v].end[1]);
      box.add(m[v].start[1]);
      box.add(m[v].end[1]);
    }
  }
  return m;
}

// Every non-excluded pair (base segment, image segment) whose swept boxes come within reach,
// each unordered pair once; calls f(base move, image move) and counts images used.
template <class F>
int for_each_pair(const RveProblem& rve, const Strain& s0, const RveState& st0, const Strain& s1, const RveState& st1,
                  double reach, F f) {
  Box base_box;
  const std::vector<SegmentMove> base = image_moves(rve, s0, st0, s1, st1, Eigen::Vector2i::Zero(), base_box);
  const int n = static_cast<int>(base.size());
  // Rings of images around the base tile, outwards until a whole ring is out of reach (the
  // shell map is injective and its images recede with the ring index); the segments of the
  // images within reach go into one list, checked against one grid of the base tile.
  std::vector<SegmentMove> all = base;
  std::vector<Eigen::Vector2i> offsets = {Eigen::Vector2i::Zero()};
  // An image whose in-plane box in both configurations (RveProblem::image_bound, from the map
  // alone) misses the base tile's swept box by more than reach is skipped unmapped: the exact
  // test would skip it too, so the pairs and the rings are the same.
  const RveProblem::ImageBound b0 = rve.image_bound(s0, st0), b1 = rve.image_bound(s1, st1);
  auto may_reach = [&](Eigen::Vector2i o) {
    Eigen::Vector2d l0, h0, l1, h1;
    b0.image_box(o, l0, h0);
    b1.image_box(o, l1, h1);
    const Eigen::Vector2d l = l0.cwiseMin(l1), h = h0.cwiseMax(h1);
    return !(((l.array() - reach) > base_box.hi.head<2>().array()).any() ||
             ((h.array() + reach) < base_box.lo.head<2>().array()).any());
  };
  for (int k = 1; k <= 64; ++k) {  // 64: a tile far smaller than its yarns
    bool any = false;
    for (int ox = -k; ox <= k; ++ox)
      for (int oy = -k; oy <= k; ++oy) {
        if (std::max(std::abs(ox), std::abs(oy)) != k) continue;
        const Eigen::Vector2i o(ox, oy);
        if (!may_reach(o)) continue;
        Box img;
        std::vector<SegmentMove> moves = image_moves(rve, s0, st0, s1, st1, o, img);
        if (!img.near(base_box, reach)) continue;
        any = true;
        all.insert(all.end(), moves.begin(), moves.end());
        offsets.push_back(o);
      }
    if (!any) break;
  }
  for (const auto& [v, j] : swept_pairs(base, all, reach)) {
    const int w = j % n;
    const Eigen::Vector2i o = offsets[j / n];
    // Each unordered pair once: (v, w at o) and (w, v at -o) are the same.
    if (v > w || (v == w && (o[0] < 0 || (o[0] == 0 && o[1] <= 0)))) continue;
    if (rve.excluded(v, w, o)) continue;
    f(base[v], all[j]);
  }
  return static_cast<int>(offsets.size());
}

}  // namespace

RveMoveCheck check_move(const RveProblem& rve, const Strain& s0, const RveState& st0, const Strain& s1,
                        const RveState& st1, double dmin, double reach) {
  RveMoveCheck r;
  const double inf = std::numeric_limits<double>::infinity();
  r.start_distance = r.end_distance = inf;
  reach = std::max(reach, dmin);
  r.images = for_each_pair(rve, s0, st0, s1, st1, reach, [&](const SegmentMove& a, const SegmentMove& b) {
    ++r.pairs;
    const auto [q0, q1] = pair_move(a, b);
    const double d1 = segment_distance(q1.segment<3>(0), q1.segment<3>(3), q1.segment<3>(6), q1.segment<3>(9));
    r.end_distance = std::min(r.end_distance, d1);
    // Only a pair that can reach dmin needs the advancement (segment_ccd checks that first).
    const CcdResult c = segment_ccd(q0, q1, dmin);
    r.start_distance = std::min(r.start_distance, c.d0);
    r.t = std::min(r.t, c.t);
  });
  return r;
}

double min_separation(const RveProblem& rve, const Strain& s, const RveState& st, double reach) {
  double d = std::numeric_limits<double>::infinity();
  for_each_pair(rve, s, st, s, st, reach, [&](const SegmentMove& a, const SegmentMove& b) {
    d = std::min(d, segment_distance(a.start[0], a.start[1], b.start[0], b.start[1]));
  });
  return d;
}

ContactCertificate certify_path(const RveProblem& rve, const std::vector<PathPoint>& path, double dmin) {
  ContactCertificate c;
  c.dmin = dmin;
  const double reach = 2.0 * rve.radius();
  if (path.empty()) {
    invalidate(c, "empty path");
    return c;
  }
  const int n = rve.pattern().size();
  for (const PathPoint& p : path)
    if (static_cast<int>(p.u.size()) != n) {
      invalidate(c, "path point of another pattern (vertex count)");
      return c;
    }
  bool origin = (path[0].s - rve.pattern_strain()).cwiseAbs().maxCoeff() <= 1e-12;
  for (const auto& u : path[0].u) origin = origin && u.isZero(0.0);
  if (!origin) invalidate(c, "the path does not start at the pattern's own geometry (u = 0 at RveProblem::pattern_strain)");
  RveState a = rve.initial_state(), b = a;
  a.u = path[0].u;
  c.min_distance = min_separation(rve, path[0].s, a, reach);
  if (!(c.min_distance > dmin)) invalidate(c, "the path's first configuration is closer than d_min");
  for (size_t i = 1; i < path.size(); ++i) {
    a.u = path[i - 1].u;
    b.u = path[i].u;
    const RveMoveCheck m = check_move(rve, path[i - 1].s, a, path[i].s, b, dmin, reach);
    add_move(c, m.t, m.end_distance, "path point " + std::to_string(i - 1) + " -> " + std::to_string(i));
  }
  return c;
}

}  // namespace yarnhom::yarn
