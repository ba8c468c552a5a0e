#include "sim/contact_broad_phase.hpp"

#include <algorithm>

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

PrimBoxes prim_boxes(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1, const Eigen::VectorXd& y0,
                     const Eigen::VectorXd& y1, double half) {
  const Mesh& m = P.mesh;
  const ObstacleSet& O = P.obstacles;
  const int n = m.num_vertices(), nt = m.num_triangles(), ne = int(P.edges.size());
  PrimBoxes B;
  B.v.resize(n);
  B.t.resize(nt);
  B.e.resize(ne);
  for (int v = 0; v < n; ++v) B.v[v] = move_box(std::array<int, 1>{v}, 1, x0, x1, half);
  for (int t = 0; t < nt; ++t) B.t[t] = move_box(tri(m, t), 3, x0, x1, half);
  for (int e = 0; e < ne; ++e) B.e[e] = move_box(P.edges[e], 2, x0, x1, half);
  if (O.empty()) return B;
  // Obstacle primitives, inflated by their radius plus half of dhat.
  const std::vector<double> radius = point_radius(O);
  B.ot.resize(O.tris.size());
  B.oe.resize(O.edges.size());
  B.op.resize(O.num_points);
  for (size_t t = 0; t < O.tris.size(); ++t) B.ot[t] = move_box(O.tris[t], 3, y0, y1, half);
  for (size_t e = 0; e < O.edges.size(); ++e) B.oe[e] = move_box(O.edges[e], 2, y0, y1, half + O.edge_radius[e]);
  for (int k = 0; k < O.num_points; ++k) B.op[k] = move_box(std::array<int, 1>{k}, 1, y0, y1, half + radius[k]);
  return B;
}

bool shares(const Problem& P, const Eigen::Vector3i& t, int v) {
  const int r = vertex_rep(P, v);
  return vertex_rep(P, t[0]) == r || vertex_rep(P, t[1]) == r || vertex_rep(P, t[2]) == r;
}

// Calls emit(group, i, j) for every pair of overlapping boxes (less those sharing a vertex), in
// the fresh broad phase's order, or (any_order) with the obstacles' few primitives in the hash
// and the cloth's many querying it: the same pairs, without hashing every cloth triangle and
// edge again for a handful of capsules.
template <class Fn>
void box_candidates(const Problem& P, const PrimBoxes& B, Fn&& emit, bool any_order = false) {
  const Mesh& m = P.mesh;
  if (P.self_collision) {
    for (const auto& [t, v] : numerics::box_pairs(B.t, B.v))
      if (!shares(P, tri(m, t), v)) emit(SelfPT, t, v);
    for (const auto& [a, b] : numerics::box_pairs(B.e, B.e, true)) {
      const Eigen::Vector2i &ea = P.edges[a], &e2 = P.edges[b];
      const int a0 = vertex_rep(P, ea[0]), a1 = vertex_rep(P, ea[1]), b0 = vertex_rep(P, e2[0]), b1 = vertex_rep(P, e2[1]);
      if (a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1) continue;
      emit(SelfEE, a, b);
    }
  }
  if (P.obstacles.empty()) return;
  for (const auto& [t, v] : numerics::box_pairs(B.ot, B.v)) emit(ObstacleTriVertex, t, v);
  if (any_order) {
    for (const auto& [k, t] : numerics::box_pairs(B.op, B.t)) emit(TriObstaclePoint, t, k);
    for (const auto& [f, e] : numerics::box_pairs(B.oe, B.e)) emit(EdgeObstacleEdge, e, f);
    return;
  }
  for (const auto& [t, k] : numerics::box_pairs(B.t, B.op)) emit(TriObstaclePoint, t, k);
  for (const auto& [e, f] : numerics::box_pairs(B.e, B.oe)) emit(EdgeObstacleEdge, e, f);
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
  std::vector<ContactPair> out;
  const std::vector<double> radius = point_radius(P.obstacles);
  box_candidates(P, prim_boxes(P, x0, x1, y0, y1, 0.5 * P.dhat),
                 [&](unsigned char g, int i, int j) { out.push_back(make_pair(P, radius, g, i, j)); });
  return out;
}

std::vector<ContactPair> contact_candidates_within(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& y,
                                                   double reach) {
  if (!has_contact(P)) return {};
  std::vector<ContactPair> out;
  const std::vector<double> radius = point_radius(P.obstacles);
  box_candidates(
      P, prim_boxes(P, x, x, y, y, 0.5 * reach),
      [&](unsigned char g, int i, int j) { out.push_back(make_pair(P, radius, g, i, j)); }, true);
  return out;
}

bool ContactCache::covers(const Eigen::VectorXd& lo, const Eigen::VectorXd& hi, const Eigen::VectorXd& p) const {
  return lo.size() == p.size() && (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
}

std::vector<ContactPair> ContactCache::candidates(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                                                  const Eigen::VectorXd& y0, const Eigen::VectorXd& y1) {
  ++queries_;
  if (!(valid_ && covers(xlo_, xhi_, x0) && covers(xlo_, xhi_, x1) && covers(ylo_, yhi_, y0) &&
        covers(ylo_, yhi_, y1))) {
    const double margin = 0.1 * P.dhat;
    xlo_ = x0.cwiseMin(x1).array() - margin;
    xhi_ = x0.cwiseMax(x1).array() + margin;
    ylo_ = y0.cwiseMin(y1).array() - margin;
    yhi_ = y0.cwiseMax(y1).array() + margin;
    entries_.clear();
    box_candidates(
        P, prim_boxes(P, xlo_, xhi_, ylo_, yhi_, 0.5 * P.dhat),
        [&](unsigned char g, int i, int j) { entries_.push_back({g, i, j}); }, true);
    valid_ = true;
    ++builds_;
  }
  const PrimBoxes B = prim_boxes(P, x0, x1, y0, y1, 0.5 * P.dhat);
  const std::vector<double> radius = point_radius(P.obstacles);
  std::vector<ContactPair> out;
  for (const Entry& e : entries_)
    if (overlaps(B, e.group, e.i, e.j)) out.push_back(make_pair(P, radius, e.group, e.i, e.j));
  return out;
}

}  // namespace yarnhom::sim
