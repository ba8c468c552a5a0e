#include "sim/contact_broad_phase.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <tuple>

#include "core/scope_profile.hpp"
#include "numerics/contact_pairs.hpp"
#include "sim/contact.hpp"

namespace yarnhom::sim {

using numerics::Box3;
using numerics::ContactKind;

namespace {

// The pair groups, in the fresh broad phase's order.
enum Group : unsigned char { SelfPT, SelfEE, ObstacleTriVertex, TriObstaclePoint, EdgeObstacleEdge };

// The primitives' boxes over a move (or a region: p0 = lo, p1 = hi).
struct PrimBoxes {
  std::vector<Box3> v, t, e, ot, oe, op;
};

std::vector<double> point_radius(const ObstacleSet& O) {
  std::vector<double> r(O.num_points, 0.0);
  for (size_t e = 0; e < O.edges.size(); ++e)
    if (O.edge_radius[e] > 0) r[O.edges[e][0]] = r[O.edges[e][1]] = O.edge_radius[e];
  return r;
}

Eigen::Vector3i tri(const Mesh& m, int t) { return m.tris.row(t).transpose(); }

// One primitive's box over the move (x0 -> x1, y0 -> y1), inflated by half (obstacle points and
// edges also by their radius): the cloth's vertex v, triangle t, edge e, the obstacles' triangle,
// edge and point k.
Box3 vertex_box(int v, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1, double half) {
  return move_box(std::array<int, 1>{v}, 1, x0, x1, half);
}
Box3 triangle_box(const Problem& P, int t, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1, double half) {
  return move_box(tri(P.mesh, t), 3, x0, x1, half);
}
Box3 edge_box(const Problem& P, int e, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1, double half) {
  return move_box(P.edges[e], 2, x0, x1, half);
}
Box3 obstacle_triangle_box(const ObstacleSet& O, int t, const Eigen::VectorXd& y0, const Eigen::VectorXd& y1, double half) {
  return move_box(O.tris[t], 3, y0, y1, half);
}
Box3 obstacle_edge_box(const ObstacleSet& O, int e, const Eigen::VectorXd& y0, const Eigen::VectorXd& y1, double half) {
  return move_box(O.edges[e], 2, y0, y1, half + O.edge_radius[e]);
}
Box3 obstacle_point_box(const std::vector<double>& radius, int k, const Eigen::VectorXd& y0, const Eigen::VectorXd& y1,
                        double half) {
  return move_box(std::array<int, 1>{k}, 1, y0, y1, half + radius[k]);
}

PrimBoxes prim_boxes(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1, const Eigen::VectorXd& y0,
                     const Eigen::VectorXd& y1, double half) {
  const Mesh& m = P.mesh;
  const ObstacleSet& O = P.obstacles;
  const int n = m.num_vertices(), nt = m.num_triangles(), ne = int(P.edges.size());
  PrimBoxes B;
  B.v.resize(n);
  B.t.resize(nt);
  B.e.resize(ne);
#pragma omp parallel if (n >= 4096)
  {
#pragma omp for schedule(static) nowait
    for (int v = 0; v < n; ++v) B.v[v] = vertex_box(v, x0, x1, half);
#pragma omp for schedule(static) nowait
    for (int t = 0; t < nt; ++t) B.t[t] = triangle_box(P, t, x0, x1, half);
#pragma omp for schedule(static) nowait
    for (int e = 0; e < ne; ++e) B.e[e] = edge_box(P, e, x0, x1, half);
  }
  if (O.empty()) return B;
  // Obstacle primitives, inflated by their radius plus half of dhat.
  const std::vector<double> radius = point_radius(O);
  B.ot.resize(O.tris.size());
  B.oe.resize(O.edges.size());
  B.op.resize(O.num_points);
  for (size_t t = 0; t < O.tris.size(); ++t) B.ot[t] = obstacle_triangle_box(O, int(t), y0, y1, half);
  for (size_t e = 0; e < O.edges.size(); ++e) B.oe[e] = obstacle_edge_box(O, int(e), y0, y1, half);
  for (int k = 0; k < O.num_points; ++k) B.op[k] = obstacle_point_box(radius, k, y0, y1, half);
  return B;
}

bool shares(const Problem& P, const Eigen::Vector3i& t, int v) {
  const int r = vertex_rep(P, v);
  return vertex_rep(P, t[0]) == r || vertex_rep(P, t[1]) == r || vertex_rep(P, t[2]) == r;
}

// Every pair of overlapping boxes (less those sharing a vertex) as lists by group, in the order
// of the groups, each list by j, then i (box_pairs' order); with any_order the obstacles' few
// primitives go in the grid and the cloth's many query it (the same pairs, sorted back into that
// order), without entering every cloth triangle and edge again for a handful of capsules.
using GroupPairs = std::pair<unsigned char, std::vector<std::pair<int, int>>>;
std::vector<GroupPairs> box_candidates(const Problem& P, const PrimBoxes& B, bool any_order = false) {
  const Mesh& m = P.mesh;
  std::vector<GroupPairs> out;
  if (P.self_collision) {
    // (the pairs sharing a vertex left out as they are found: most of a sheet's overlapping
    // edge boxes are a vertex's edges)
    out.emplace_back(SelfPT, numerics::box_pairs(B.t, B.v, false, [&](int t, int v) { return !shares(P, tri(m, t), v); }));
    const auto apart = [&](int a, int b) {
      const Eigen::Vector2i &ea = P.edges[a], &e2 = P.edges[b];
      const int a0 = vertex_rep(P, ea[0]), a1 = vertex_rep(P, ea[1]), b0 = vertex_rep(P, e2[0]), b1 = vertex_rep(P, e2[1]);
      return !(a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1);
    };
    out.emplace_back(SelfEE, numerics::box_pairs(B.e, B.e, true, apart));
  }
  if (P.obstacles.empty()) return out;
  out.emplace_back(ObstacleTriVertex, numerics::box_pairs(B.ot, B.v));
  if (any_order) {
    // (sorted back into the fresh order: by the obstacle's primitive, then the cloth's)
    std::vector<std::pair<int, int>> tk = numerics::box_pairs(B.op, B.t), ef = numerics::box_pairs(B.oe, B.e);
    std::sort(tk.begin(), tk.end());
    std::sort(ef.begin(), ef.end());
    for (auto* l : {&tk, &ef})
      for (auto& [a, b] : *l) std::swap(a, b);
    out.emplace_back(TriObstaclePoint, std::move(tk));
    out.emplace_back(EdgeObstacleEdge, std::move(ef));
    return out;
  }
  out.emplace_back(TriObstaclePoint, numerics::box_pairs(B.t, B.op));
  out.emplace_back(EdgeObstacleEdge, numerics::box_pairs(B.e, B.oe));
  return out;
}

// The lists' pairs made into T by make(group, i, j), in the lists' order, on the OpenMP threads
// (hundreds of thousands of pairs in a T-shirt's region).
template <class Vec, class Make>
Vec flatten(const std::vector<GroupPairs>& lists, Make&& make) {
  size_t total = 0;
  for (const auto& l : lists) total += l.second.size();
  Vec out(total);
  size_t off = 0;
  for (const auto& [g, l] : lists) {
    const int64_t n = int64_t(l.size());
#pragma omp parallel for schedule(static) if (n >= 8192)
    for (int64_t k = 0; k < n; ++k) out[off + size_t(k)] = make(g, l[size_t(k)].first, l[size_t(k)].second);
    off += l.size();
  }
  return out;
}

bool overlaps(const PrimBoxes& B, unsigned char g, int i, int j) {
  switch (g) {
    case SelfPT: return B.t[i].overlaps(B.v[j]);
    case SelfEE: return B.e[i].overlaps(B.e[j]);
    case ObstacleTriVertex: return B.ot[i].overlaps(B.v[j]);
    case TriObstaclePoint: return B.t[i].overlaps(B.op[j]);
    default: return B.e[i].overlaps(B.oe[j]);
  }
}

ContactPair make_pair(const Problem& P, const std::vector<double>& radius, unsigned char g, int i, int j) {
  const ObstacleSet& O = P.obstacles;
  switch (g) {
    case SelfPT: {
      const Eigen::Vector3i T = tri(P.mesh, i);
      return {ContactKind::PointTriangle, {j, T[0], T[1], T[2]}, 0.0, P.self_friction};
    }
    case SelfEE:
      return {ContactKind::EdgeEdge, {P.edges[i][0], P.edges[i][1], P.edges[j][0], P.edges[j][1]}, 0.0, P.self_friction};
    case ObstacleTriVertex: {
      const Eigen::Vector3i& T = O.tris[i];
      return {ContactKind::PointTriangle, {j, -1 - T[0], -1 - T[1], -1 - T[2]}, 0.0, O.tri_friction[i]};
    }
    case TriObstaclePoint: {
      const Eigen::Vector3i T = tri(P.mesh, i);
      return {ContactKind::PointTriangle, {-1 - j, T[0], T[1], T[2]}, radius[j], O.point_friction[j]};
    }
    default: {
      const Eigen::Vector2i& E = O.edges[j];
      return {ContactKind::EdgeEdge, {P.edges[i][0], P.edges[i][1], -1 - E[0], -1 - E[1]}, O.edge_radius[j],
              O.edge_friction[j]};
    }
  }
}

}  // namespace

std::vector<ContactPair> contact_candidates(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                                            const Eigen::VectorXd& y0, const Eigen::VectorXd& y1, ContactCache* cache) {
  if (!has_contact(P)) return {};
  if (cache) return cache->candidates(P, x0, x1, y0, y1);
  prof::Scope ps("broad phase: without a cache");
  const std::vector<double> radius = point_radius(P.obstacles);
  return flatten<std::vector<ContactPair>>(box_candidates(P, prim_boxes(P, x0, x1, y0, y1, 0.5 * P.dhat)),
                              [&](unsigned char g, int i, int j) { return make_pair(P, radius, g, i, j); });
}

std::vector<ContactPair> contact_candidates_within(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& y,
                                                   double reach) {
  if (!has_contact(P)) return {};
  prof::Scope ps("broad phase: within a reach");
  const std::vector<double> radius = point_radius(P.obstacles);
  return flatten<std::vector<ContactPair>>(box_candidates(P, prim_boxes(P, x, x, y, y, 0.5 * reach), true),
                              [&](unsigned char g, int i, int j) { return make_pair(P, radius, g, i, j); });
}

bool ContactCache::covers(const Eigen::VectorXd& lo, const Eigen::VectorXd& hi, const Eigen::VectorXd& p) const {
  return lo.size() == p.size() && (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
}

void ContactCache::cover(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                         const Eigen::VectorXd& y0, const Eigen::VectorXd& y1) {
  ++queries_;
  if (valid_ && covers(xlo_, xhi_, x0) && covers(xlo_, xhi_, x1) && covers(ylo_, yhi_, y0) && covers(ylo_, yhi_, y1))
    return;
  prof::Scope ps("broad phase: a region built");
  const double margin = 0.1 * P.dhat;
  xlo_ = x0.cwiseMin(x1).array() - margin;
  xhi_ = x0.cwiseMax(x1).array() + margin;
  ylo_ = y0.cwiseMin(y1).array() - margin;
  yhi_ = y0.cwiseMax(y1).array() + margin;
  radius_ = point_radius(P.obstacles);
  RawVector<Entry> old;
  RawVector<double> old_gap;
  if (snapped_) old.swap(entries_), old_gap.swap(gap_);
  entries_.clear();
  PrimBoxes boxes;
  {
    prof::Scope pb("broad phase: boxes");
    boxes = prim_boxes(P, xlo_, xhi_, ylo_, yhi_, 0.5 * P.dhat);
  }
  std::vector<GroupPairs> lists = box_candidates(P, boxes, true);
  {
    prof::Scope pe("broad phase: the region's entries");
    entries_ = flatten<RawVector<Entry>>(lists, [](unsigned char g, int i, int j) { return Entry{g, i, j}; });
  }
  prof::Scope pm("broad phase: merged with the last region");
  valid_ = true;
  ++builds_;
  // A pair of the old region keeps its bound at the snapshot (a bound of its distance there,
  // whatever the region); a new pair has none (-inf: computed at its first query). Both lists
  // are sorted by (group, j, i) (box_candidates' order): one merge.
  gap_.resize(entries_.size());
  const auto key = [](const Entry& e) { return std::make_tuple(e.group, e.j, e.i); };
  const auto by_key = [&](const Entry& a, const Entry& b) { return key(a) < key(b); };
  // (the new list checked on the threads; the old one was checked when it was new)
  const int64_t n = int64_t(entries_.size());
  bool sorted = true;
#pragma omp parallel for schedule(static) reduction(&& : sorted) if (n >= 16384)
  for (int64_t k = 1; k < n; ++k) sorted = sorted && !by_key(entries_[size_t(k)], entries_[size_t(k - 1)]);
  const bool old_sorted = sorted_;
  sorted_ = sorted;
  const bool merge = snapped_ && old_sorted && sorted;
  snapped_ = merge;
  // (the new list in chunks on the threads, each chunk's first old twin found by bisection and
  // the rest by walking both lists: the same as one merge)
  constexpr int64_t kChunk = 4096;
#pragma omp parallel for schedule(static) if (n >= 16384)
  for (int64_t c = 0; c < (n + kChunk - 1) / kChunk; ++c) {
    const int64_t k0 = c * kChunk, k1 = std::min(n, k0 + kChunk);
    auto it = merge ? std::lower_bound(old.begin(), old.end(), entries_[size_t(k0)], by_key) : old.end();
    for (int64_t k = k0; k < k1; ++k) {
      const Entry& e = entries_[size_t(k)];
      while (it != old.end() && by_key(*it, e)) ++it;
      gap_[size_t(k)] = it != old.end() && key(*it) == key(e) ? old_gap[size_t(it - old.begin())]
                                                              : -std::numeric_limits<double>::infinity();
    }
  }
}

ContactPair ContactCache::pair_of(const Problem& P, const Entry& e) const { return make_pair(P, radius_, e.group, e.i, e.j); }

bool ContactCache::entry_overlaps(const Problem& P, const Entry& e, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                                  const Eigen::VectorXd& y0, const Eigen::VectorXd& y1) const {
  const double half = 0.5 * P.dhat;
  const ObstacleSet& O = P.obstacles;
  switch (e.group) {
    case SelfPT: return triangle_box(P, e.i, x0, x1, half).overlaps(vertex_box(e.j, x0, x1, half));
    case SelfEE: return edge_box(P, e.i, x0, x1, half).overlaps(edge_box(P, e.j, x0, x1, half));
    case ObstacleTriVertex: return obstacle_triangle_box(O, e.i, y0, y1, half).overlaps(vertex_box(e.j, x0, x1, half));
    case TriObstaclePoint:
      return triangle_box(P, e.i, x0, x1, half).overlaps(obstacle_point_box(radius_, e.j, y0, y1, half));
    default: return edge_box(P, e.i, x0, x1, half).overlaps(obstacle_edge_box(O, e.j, y0, y1, half));
  }
}

std::vector<ContactPair> ContactCache::candidates(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                                                  const Eigen::VectorXd& y0, const Eigen::VectorXd& y1) {
  cover(P, x0, x1, y0, y1);
  const PrimBoxes B = prim_boxes(P, x0, x1, y0, y1, 0.5 * P.dhat);
  std::vector<ContactPair> out;
  for (const Entry& e : entries_)
    if (overlaps(B, e.group, e.i, e.j)) out.push_back(pair_of(P, e));
  return out;
}

namespace {

// The moves of a pair's four points, from per-point moves of the cloth (dx) and the obstacles (dy).
numerics::Vec12 pair_move(const ContactPair& c, const Eigen::VectorXd& dx, const Eigen::VectorXd& dy) {
  numerics::Vec12 q;
  for (int k = 0; k < 4; ++k) q.segment<3>(3 * k) = c.slot[k] >= 0 ? dx.segment<3>(3 * c.slot[k]) : dy.segment<3>(3 * (-1 - c.slot[k]));
  return q;
}

bool has_obstacle_point(const ContactPair& c) {
  return c.slot[0] < 0 || c.slot[1] < 0 || c.slot[2] < 0 || c.slot[3] < 0;
}

}  // namespace

namespace {

// Runs keep(k, out) for the entries k in [0, n), in fixed chunks on the OpenMP threads (each
// chunk's pairs in its own list, the lists joined in order: the result does not depend on the
// thread count); keep returns 1 when it computed a distance. Returns their count.
template <class Keep>
long entries_in_chunks(size_t n, std::vector<ContactPair>& out, Keep&& keep) {
  constexpr size_t kChunk = 1024;  // 100-500k entries on the T-shirt: a hundred chunks or more for 16 threads
  const int64_t nchunks = int64_t((n + kChunk - 1) / kChunk);
  std::vector<std::vector<ContactPair>> part(static_cast<size_t>(nchunks));
  long distances = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : distances) if (nchunks > 1)
  for (int64_t c = 0; c < nchunks; ++c)
    for (size_t k = size_t(c) * kChunk; k < std::min(n, size_t(c + 1) * kChunk); ++k) distances += keep(k, part[size_t(c)]);
  for (const auto& p : part) out.insert(out.end(), p.begin(), p.end());
  return distances;
}

}  // namespace

std::vector<ContactPair> ContactCache::near(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  cover(P, x, x, y, y);
  const double m = 1e-4 * P.dhat, need = P.dhat + m;
  Eigen::VectorXd dx, dy;
  if (snapped_) dx = x - sx_, dy = y - sy_;
  std::vector<ContactPair> out;
  distances_ += entries_in_chunks(entries_.size(), out, [&](size_t k, std::vector<ContactPair>& o) {
    const Entry& e = entries_[k];
    const ContactPair c = pair_of(P, e);
    if (snapped_) {
      const double g = gap_[k] - numerics::contact_speed(c.kind, pair_move(c, dx, dy));
      if (g >= need) {
        gap_[k] = g;
        return 0;
      }
    }
    gap_[k] = numerics::contact_distance(c.kind, pair_coordinates(c, x, y)) - c.dmin;
    if (gap_[k] < need && entry_overlaps(P, e, x, x, y, y)) o.push_back(c);
    return 1;
  });
  sx_ = x;
  sy_ = y;
  snapped_ = true;
  return out;
}

std::vector<ContactPair> ContactCache::ccd_candidates(const Problem& P, const Eigen::VectorXd& x0,
                                                      const Eigen::VectorXd& x1, const Eigen::VectorXd& y0,
                                                      const Eigen::VectorXd& y1) {
  cover(P, x0, x1, y0, y1);
  const double m = 1e-4 * P.dhat;
  Eigen::VectorXd dx, dy;
  if (snapped_) dx = x0 - sx_, dy = y0 - sy_;
  const Eigen::VectorXd mx = x1 - x0, my = y1 - y0;
  std::vector<ContactPair> out;
  distances_ += entries_in_chunks(entries_.size(), out, [&](size_t k, std::vector<ContactPair>& o) {
    const Entry& e = entries_[k];
    const ContactPair c = pair_of(P, e);
    const double f = has_obstacle_point(c) ? kObstacleFloor * P.dhat : 0.0;
    const double l = numerics::contact_speed(c.kind, pair_move(c, mx, my));
    auto safe = [&](double g) { return (1 - kContactEta) * (g - f) - l >= m; };
    if (snapped_) {
      const double g = gap_[k] - numerics::contact_speed(c.kind, pair_move(c, dx, dy));
      if (safe(g)) {
        gap_[k] = g;
        return 0;
      }
    }
    gap_[k] = numerics::contact_distance(c.kind, pair_coordinates(c, x0, y0)) - c.dmin;
    if (!safe(gap_[k]) && entry_overlaps(P, e, x0, x1, y0, y1)) o.push_back(c);
    return 1;
  });
  sx_ = x0;
  sy_ = y0;
  snapped_ = true;
  return out;
}

}  // namespace yarnhom::sim
