#include "sim/contact.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>

#include "core/scope_profile.hpp"
#include "numerics/contact_pairs.hpp"
#include "sim/contact_broad_phase.hpp"
#include "numerics/psd_projection.hpp"
#include "sim/friction.hpp"

namespace yarnhom::sim {

using numerics::Box3;
using numerics::ContactKind;
using numerics::Vec12;
using numerics::Mat12;
using V3 = Eigen::Vector3d;

std::vector<Eigen::Vector2i> cloth_edges(const Mesh& mesh) {
  std::vector<Eigen::Vector2i> e;
  for (int t = 0; t < mesh.num_triangles(); ++t)
    for (int i = 0; i < 3; ++i) {
      int a = mesh.tris(t, i), b = mesh.tris(t, (i + 1) % 3);
      if (a > b) std::swap(a, b);
      e.emplace_back(a, b);
    }
  std::sort(e.begin(), e.end(), [](const Eigen::Vector2i& p, const Eigen::Vector2i& q) {
    return p[0] != q[0] ? p[0] < q[0] : p[1] < q[1];
  });
  e.erase(std::unique(e.begin(), e.end()), e.end());
  return e;
}

bool has_contact(const Problem& P) { return P.self_collision || !P.obstacles.empty(); }

namespace {

V3 at(const Eigen::VectorXd& v, int k) { return v.segment<3>(3 * k); }

// Point k of the slot's owner at (x, y).
V3 slot_position(int s, const Eigen::VectorXd& x, const Eigen::VectorXd& y) { return s >= 0 ? at(x, s) : at(y, -1 - s); }

}  // namespace

Vec12 pair_coordinates(const ContactPair& c, const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  Vec12 q;
  for (int k = 0; k < 4; ++k) q.segment<3>(3 * k) = slot_position(c.slot[k], x, y);
  return q;
}

namespace {
double pair_area(const Problem& P, const ContactPair& c) {
  double A = 0;
  int n = 0;
  for (int s : c.slot)
    if (s >= 0) A += P.vertex_area[s], ++n;
  return n ? A / n : 0.0;
}

// Adds a 12 x 12 block matrix over the pair's slots to the triplets (lower triangle, free
// vertices only), and a 12-gradient to grad.
void scatter_pair(const ContactPair& c, const std::vector<int>& free_index, const Vec12* g, const Mat12* H,
                  Eigen::VectorXd* grad, std::vector<Eigen::Triplet<double>>* trip) {
  for (int k = 0; k < 4; ++k) {
    const int vk = c.slot[k];
    if (vk < 0) continue;
    if (grad && g) grad->segment<3>(3 * vk) += g->segment<3>(3 * k);
    if (!trip || !H) continue;
    const int fk = free_index[vk];
    if (fk < 0) continue;
    for (int l = 0; l < 4; ++l) {
      const int vl = c.slot[l];
      if (vl < 0) continue;
      const int fl = free_index[vl];
      if (fl < 0 || fk < fl) continue;
      for (int col = 0; col < 3; ++col)
        for (int row = fk == fl ? col : 0; row < 3; ++row) {
          const double h = (*H)(3 * k + row, 3 * l + col);
          if (h != 0) trip->emplace_back(3 * fk + row, 3 * fl + col, h);
        }
    }
  }
}

// Sum over n pair terms, term(k, g, H) returning the k-th term's value (and its gradient and
// Hessian where asked; with zero_is_none a term of 0 has none: a barrier beyond its reach),
// pair(k) its pair. The terms are evaluated in fixed
// chunks on the OpenMP threads (a T-shirt on a body holds thousands of pairs, each a 12 x 12
// Hessian and its PSD projection), their Hessians made into triplets per chunk; then the values
// are summed, the gradients added and the chunks' triplets appended in the pairs' order, as one
// thread in a loop over the pairs would (the same result on any thread count). An infinite
// term ends the sum: infinity, with what came before it added (triplets not).
template <class Term, class PairOf>
double sum_pair_terms(size_t n, const std::vector<int>& free_index, Eigen::VectorXd* grad,
                      std::vector<Eigen::Triplet<double>>* trip, bool zero_is_none, Term&& term, PairOf&& pair) {
  constexpr size_t kChunk = 64;
  const int64_t nchunks = int64_t((n + kChunk - 1) / kChunk);
  std::vector<double> e(n, 0.0);
  std::vector<Vec12> g(grad ? n : 0);
  std::vector<std::vector<Eigen::Triplet<double>>> part(trip ? size_t(nchunks) : 0);
  std::optional<prof::Scope> phase(std::in_place, "contact: the pairs' terms");
#pragma omp parallel for schedule(dynamic, 1) if (n >= 4 * kChunk)
  for (int64_t c = 0; c < nchunks; ++c) {
    Mat12 H;
    for (size_t k = size_t(c) * kChunk; k < std::min(n, size_t(c + 1) * kChunk); ++k) {
      e[k] = term(k, grad ? &g[k] : nullptr, trip ? &H : nullptr);
      if (trip && (e[k] != 0 || !zero_is_none) && std::isfinite(e[k])) scatter_pair(pair(k), free_index, nullptr, &H, nullptr, &part[size_t(c)]);
    }
  }
  phase.emplace("contact: the terms summed, their triplets joined");
  double E = 0;
  for (size_t k = 0; k < n; ++k) {
    if (e[k] == 0 && zero_is_none) continue;
    if (!std::isfinite(e[k])) return std::numeric_limits<double>::infinity();
    E += e[k];
    if (grad) scatter_pair(pair(k), free_index, &g[k], nullptr, grad, nullptr);
  }
  if (trip) {  // the chunks' triplets in order, copied on the threads (hundreds of thousands)
    std::vector<size_t> at(part.size() + 1, trip->size());
    for (size_t c = 0; c < part.size(); ++c) at[c + 1] = at[c] + part[c].size();
    trip->resize(at.back());
#pragma omp parallel for schedule(static) if (at.back() - at.front() >= 65536)
    for (int64_t c = 0; c < nchunks; ++c) std::copy(part[size_t(c)].begin(), part[size_t(c)].end(), trip->begin() + int64_t(at[size_t(c)]));
  }
  return E;
}
}  // namespace

numerics::BarrierParams pair_barrier(const Problem& P, const ContactPair& c) {
  return {c.dmin, c.dmin + P.dhat, P.kappa * pair_area(P, c) * P.dhat};
}

double contact_energy(const Problem& P, const std::vector<int>& free_index, const Eigen::VectorXd& x,
                      const Eigen::VectorXd& y, Eigen::VectorXd* grad, std::vector<Eigen::Triplet<double>>* trip,
                      ContactCache* cache) {
  if (!has_contact(P)) return 0.0;
  // The cache leaves out pairs shown beyond d_hat: their terms are zero (skipped below).
  std::vector<ContactPair> pairs;
  {
    prof::Scope ps("contact: the near pairs");
    pairs = cache ? cache->near(P, x, y) : contact_candidates(P, x, x, y, y);
  }
  return sum_pair_terms(
      pairs.size(), free_index, grad, trip, true,
      [&](size_t k, Vec12* g, Mat12* H) {
        const ContactPair& c = pairs[k];
        const double e = numerics::contact_barrier_energy(c.kind, pair_coordinates(c, x, y), pair_barrier(P, c), g, H);
        if (H && e != 0 && std::isfinite(e)) numerics::project_psd<12>(*H);
        return e;
      },
      [&](size_t k) -> const ContactPair& { return pairs[k]; });
}

namespace {

// One pair's CCD bound over the move (x0 -> x1, y0 -> y1) (contact_step_bound below), its hits
// appended to hits when the bound is below 1.
double pair_step_bound(const Problem& P, const ContactPair& c, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                       const Eigen::VectorXd& y0, const Eigen::VectorXd& y1, std::vector<ContactHit>* hits) {
  const Vec12 q0 = pair_coordinates(c, x0, y0), q1 = pair_coordinates(c, x1, y1);
  if (q0 == q1) return 1.0;
  numerics::CcdResult r = numerics::contact_ccd(c.kind, q0, q1, c.dmin, kContactEta);
  // A moving obstacle never comes closer than dmin + dhat / 10 to the cloth on its own: with
  // the cloth pinched against something fixed, the bound above would let it close 90 % of the
  // gap stage after stage, down to rounding (and through). Within that, it may only move
  // where the pair's distance does not shrink by more than kFloorCreep of its gap (checked at
  // the fractions a stage may take): a cloth edge carried along with a body whose OBJ frames
  // are rounded (9 digits) lost 2e-12 m over a 1.7 cm move, which held the body back for good
  // when nothing was allowed; a pinched vertex that stays loses its whole gap at once.
  bool moving = false;
  for (int k = 0; k < 4; ++k) moving = moving || (c.slot[k] < 0 && q0.segment<3>(3 * k) != q1.segment<3>(3 * k));
  if (moving && r.t > 0) {
    const double floor = c.dmin + kObstacleFloor * P.dhat;
    if (r.d0 > floor) {
      r.t = std::min(r.t, numerics::contact_ccd(c.kind, q0, q1, floor, kContactEta).t);
    } else {  // (a vertex carried along keeps its distance, to the obstacle's rounding)
      for (double s : {0.1, 0.25, 0.5, 0.75, 0.9, 1.0})
        if (numerics::contact_distance(c.kind, q0 + s * (q1 - q0)) < r.d0 - 1e-9 * P.dhat - kFloorCreep * (r.d0 - c.dmin)) {
          r.t = 0;
          break;
        }
    }
  }
  if (!(r.t < 1)) return 1.0;
  if (!hits) return r.t;
  ContactHit h;
  int n = 0;
  for (int k = 0; k < 4; ++k)
    if (c.slot[k] < 0) h.carry += q1.segment<3>(3 * k) - q0.segment<3>(3 * k), ++n;
  h.obstacle = n > 0;
  h.gap = r.d0 - c.dmin;
  if (n) h.carry /= n;
  h.slot = c.slot;
  for (int s : c.slot)
    if (s >= 0) {
      h.vertex = s;
      hits->push_back(h);
    }
  return r.t;
}

}  // namespace

double contact_step_bound(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& dx,
                          const Eigen::VectorXd& y0, const Eigen::VectorXd& dy, std::vector<ContactHit>* hits,
                          ContactCache* cache) {
  if (!has_contact(P)) return 1.0;
  if (!(dx.cwiseAbs().maxCoeff() > 0) && !(dy.size() && dy.cwiseAbs().maxCoeff() > 0)) return 1.0;  // no move
  const Eigen::VectorXd x1 = x0 + dx, y1 = y0 + dy;
  // The cache leaves out pairs shown to give t = 1 below.
  const std::vector<ContactPair> pairs =
      cache ? cache->ccd_candidates(P, x0, x1, y0, y1) : contact_candidates(P, x0, x1, y0, y1);
  // The pairs in fixed chunks on the OpenMP threads, each chunk's hits in its own list, joined in
  // order (the bound is a minimum): the result does not depend on the thread count.
  constexpr size_t kChunk = 256;
  const int64_t nchunks = int64_t((pairs.size() + kChunk - 1) / kChunk);
  std::vector<double> t(static_cast<size_t>(nchunks), 1.0);
  std::vector<std::vector<ContactHit>> part(hits ? static_cast<size_t>(nchunks) : 0);
#pragma omp parallel for schedule(dynamic, 1) if (nchunks > 1)
  for (int64_t c = 0; c < nchunks; ++c)
    for (size_t k = size_t(c) * kChunk; k < std::min(pairs.size(), size_t(c + 1) * kChunk); ++k)
      t[size_t(c)] = std::min(t[size_t(c)], pair_step_bound(P, pairs[k], x0, x1, y0, y1, hits ? &part[size_t(c)] : nullptr));
  if (hits)
    for (const auto& h : part) hits->insert(hits->end(), h.begin(), h.end());
  double bound = 1.0;
  for (double tc : t) bound = std::min(bound, tc);
  return bound;
}

double make_move_safe(const Problem& P, const std::vector<int>& free_index, const Eigen::VectorXd& x0,
                      Eigen::VectorXd& x1, const Eigen::VectorXd& y0, const Eigen::VectorXd& y1, int rounds,
                      ContactCache* cache) {
  if (!has_contact(P)) return 1.0;
  const Eigen::VectorXd dy = y1 - y0;
  // 1 held at x0, 2 carried by an obstacle (since round carried[v]), 3 held for good
  std::vector<char> state(P.mesh.num_vertices(), 0);
  std::vector<int> carried(P.mesh.num_vertices(), 0);
  for (int round = 0;; ++round) {
    std::vector<ContactHit> hits;
    const double t = contact_step_bound(P, x0, x1 - x0, y0, dy, &hits, cache);
    if (t >= 1 || round == rounds) return t;
    bool changed = false;
    for (const ContactHit& h : hits) {
      const int v = h.vertex;
      if (free_index[v] < 0 || state[v] == 3) continue;
      if (state[v] == 2) {
        // Carried in an earlier round and still limiting against an obstacle that moves
        // otherwise (by more than a tenth of the pair's gap): carried into another one
        // (pinched). It stays instead, and holds the carrying obstacle back. Limiting against
        // an obstacle that moves as it is carried, the pair's other cloth vertices are not yet
        // (they are carried this round): no pinch.
        if (!h.obstacle || carried[v] == round) continue;
        if ((h.carry - (at(x1, v) - at(x0, v))).norm() <= 0.1 * h.gap) continue;
        state[v] = 3;
        x1.segment<3>(3 * v) = at(x0, v);
        changed = true;
        continue;
      }
      // A vertex of a self pair with a carried vertex is pushed along: carried by that
      // vertex's carry (the next cloth layer ahead of a moving body), instead of staying and
      // holding the carried layer, and with it the body, back. A prescribed one stays.
      bool carry = h.obstacle;
      V3 by = h.carry;
      if (!h.obstacle)
        for (int u : h.slot)
          if (u >= 0 && u != v && state[u] == 2) {
            carry = true;
            by = at(x1, u) - at(x0, u);
            break;
          }
      // A carry that would take the vertex into a collider is refused: the vertex stays (and
      // holds the obstacle back) instead of being pushed through the floor.
      bool refused = false;
      for (const Collider& c : P.colliders)
        refused = refused || (carry && collider_time_of_impact(c, at(x0, v), by) < 1.0);
      const V3 to = carry && !refused ? V3(at(x0, v) + by) : at(x0, v);
      if (refused) state[v] = 3;
      else if (carry) state[v] = 2, carried[v] = round;
      else if (state[v] == 1) continue;
      else state[v] = 1;
      if (to != at(x1, v)) {
        x1.segment<3>(3 * v) = to;
        changed = true;
      }
    }
    if (!changed) return t;
  }
}

std::vector<PairFriction> pair_friction_contacts(const Problem& P, const Eigen::VectorXd& x_at, const Eigen::VectorXd& y_at,
                                                 const Eigen::VectorXd& x_start, const Eigen::VectorXd& y_start,
                                                 ContactCache* cache) {
  std::vector<PairFriction> out;
  if (!has_contact(P)) return out;
  // The cache leaves out pairs shown beyond their activation distance (skipped below).
  for (const ContactPair& c : cache ? cache->near(P, x_at, y_at) : contact_candidates(P, x_at, x_at, y_at, y_at)) {
    if (!(c.mu > 0)) continue;
    const Vec12 q = pair_coordinates(c, x_at, y_at);
    const double d = numerics::contact_distance(c.kind, q);
    const numerics::BarrierParams bp = pair_barrier(P, c);
    if (!(d < bp.dhat) || !(d > bp.dmin)) continue;
    const double span = bp.dhat * bp.dhat - bp.dmin * bp.dmin;
    double b1;
    numerics::barrier((d * d - bp.dmin * bp.dmin) / span, &b1);
    PairFriction f;
    f.pair = c;
    f.w = numerics::contact_weights(c.kind, q);
    V3 r = V3::Zero();
    for (int k = 0; k < 4; ++k) r += f.w[k] * q.segment<3>(3 * k);
    if (!(r.norm() > 0)) continue;
    f.T = tangent_basis(r / r.norm());
    f.mu_lambda = c.mu * bp.kappa * std::abs(b1) * 2 * d / span;
    f.q_start = pair_coordinates(c, x_start, y_start);
    if (f.mu_lambda > 0) out.push_back(f);
  }
  return out;
}

double pair_friction_energy(const std::vector<PairFriction>& F, double eps, const std::vector<int>& free_index,
                            const Eigen::VectorXd& x, const Eigen::VectorXd& y, Eigen::VectorXd* grad,
                            std::vector<Eigen::Triplet<double>>* trip, bool majorize) {
  return sum_pair_terms(
      F.size(), free_index, grad, trip, false,
      [&](size_t i, Vec12* g, Mat12* H) {
        const PairFriction& f = F[i];
        const Vec12 q = pair_coordinates(f.pair, x, y);
        V3 slip = V3::Zero();
        for (int k = 0; k < 4; ++k) slip += f.w[k] * (q.segment<3>(3 * k) - f.q_start.segment<3>(3 * k));
        const Eigen::Vector2d u = f.T.transpose() * slip;
        const FrictionMollifier m = friction_mollifier(u.norm(), eps);
        const double e = f.mu_lambda * m.f0;
        if (!g && !H) return e;
        const V3 gs = f.mu_lambda * m.f1_over_y * (f.T * u);
        Eigen::Matrix2d Hu = majorize ? Eigen::Matrix2d(m.f1_over_y * Eigen::Matrix2d::Identity())
                                      : Eigen::Matrix2d(m.f1_over_y * Eigen::Matrix2d::Identity() + m.uu_coeff * u * u.transpose());
        numerics::project_psd<2>(Hu);
        const Eigen::Matrix3d Hs = f.mu_lambda * f.T * Hu * f.T.transpose();
        for (int k = 0; k < 4; ++k) {
          if (g) g->segment<3>(3 * k) = f.w[k] * gs;
          if (H)
            for (int l = 0; l < 4; ++l) H->block<3, 3>(3 * k, 3 * l) = f.w[k] * f.w[l] * Hs;
        }
        return e;
      },
      [&](size_t i) -> const ContactPair& { return F[i].pair; });
}

bool contact_intersections(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& y, std::string* what) {
  const Mesh& m = P.mesh;
  const int nt = m.num_triangles();
  std::vector<Box3> tb(nt);
  for (int t = 0; t < nt; ++t) tb[t] = move_box(Eigen::Vector3i(m.tris.row(t).transpose()), 3, x, x, 0.0);
  auto tri = [&](int t, int i) { return at(x, m.tris(t, i)); };
  const auto apart = [&](int a, int b) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (vertex_rep(P, m.tris(a, i)) == vertex_rep(P, m.tris(b, j))) return false;
    return true;
  };
  for (const auto& [a, b] : numerics::box_pairs(tb, tb, true, apart)) {
    if (numerics::triangles_intersect(tri(a, 0), tri(a, 1), tri(a, 2), tri(b, 0), tri(b, 1), tri(b, 2))) {
      if (what) *what = "cloth triangles " + std::to_string(a) + " and " + std::to_string(b) + " intersect";
      return true;
    }
  }
  const ObstacleSet& O = P.obstacles;
  if (O.empty()) return false;
  std::vector<Box3> ot(O.tris.size());
  for (size_t t = 0; t < O.tris.size(); ++t) ot[t] = move_box(O.tris[t], 3, y, y, 0.0);
  for (const auto& [o, t] : numerics::box_pairs(ot, tb)) {
    const Eigen::Vector3i& T = O.tris[o];
    if (numerics::triangles_intersect(at(y, T[0]), at(y, T[1]), at(y, T[2]), tri(t, 0), tri(t, 1), tri(t, 2))) {
      if (what) *what = "cloth triangle " + std::to_string(t) + " meets obstacle triangle " + std::to_string(o);
      return true;
    }
  }
  std::vector<Box3> oe;
  std::vector<int> caps;
  for (size_t e = 0; e < O.edges.size(); ++e)
    if (O.edge_radius[e] > 0) {
      oe.push_back(move_box(O.edges[e], 2, y, y, O.edge_radius[e]));
      caps.push_back(int(e));
    }
  for (const auto& [k, t] : numerics::box_pairs(oe, tb)) {
    const int e = caps[k];
    const V3 a = at(y, O.edges[e][0]), b = at(y, O.edges[e][1]);
    const double r = O.edge_radius[e];
    // Segment-triangle distance: 0 when the axis crosses the triangle, else the closest of
    // its ends to the triangle and of the triangle's edges to it.
    bool in = numerics::segment_triangle_intersect(a, b, tri(t, 0), tri(t, 1), tri(t, 2));
    in = in || numerics::point_triangle_distance(a, tri(t, 0), tri(t, 1), tri(t, 2)) <= r ||
         numerics::point_triangle_distance(b, tri(t, 0), tri(t, 1), tri(t, 2)) <= r;
    for (int i = 0; i < 3 && !in; ++i) in = numerics::segment_distance(tri(t, i), tri(t, (i + 1) % 3), a, b) <= r;
    if (in) {
      if (what) *what = "cloth triangle " + std::to_string(t) + " is within the radius of capsule edge " + std::to_string(e);
      return true;
    }
  }
  return false;
}

}  // namespace yarnhom::sim
