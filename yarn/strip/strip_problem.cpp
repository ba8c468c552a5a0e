#include "yarn/strip/strip_problem.hpp"

#include <omp.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "numerics/hash_grid.hpp"
#include "numerics/psd_projection.hpp"

namespace yarnhom::yarn {

using numerics::Vec12;
using numerics::Mat12;
using numerics::segment_distance;
using numerics::Box3;
using numerics::overlapping_pairs;
using numerics::BlockHessian;

StripProblem::StripProblem(Strip strip, Material material, std::vector<signed char> clamp, StripOptions options)
    : s_(std::move(strip)), m_(material), clamp_(std::move(clamp)), opt_(options),
      contact_(s_.radius, material.contact_stiffness * s_.radius, options.contact) {
  check_strip(s_);
  const int n = s_.size(), ne = s_.num_edges();
  if (static_cast<int>(clamp_.size()) != n) throw std::invalid_argument("strip problem: one clamp flag per vertex expected");
  const double r = s_.radius;
  EA_ = m_.young * M_PI * r * r;
  EI_ = m_.young * M_PI * r * r * r * r / 4.0;
  GJ_ = m_.shear * M_PI * r * r * r * r / 2.0;
  // Unknowns per vertex v: its position (free vertices), then the twist angle of edge v
  // (unless both its ends are clamped): one node of the block Hessian.
  std::vector<double> scale;
  pos_index_.assign(n, -1);
  theta_index_.assign(ne, -1);
  node_first_.assign(n, 0);
  node_count_.assign(n, 0);
  for (int v = 0; v < n; ++v) {
    node_first_[v] = ndof_;
    if (clamp_[v] == 0) {
      pos_index_[v] = ndof_;
      ndof_ += 3;
      scale.insert(scale.end(), 3, 1.0);
    }
    if (v < ne && (clamp_[v] == 0 || clamp_[s_.next(v)] == 0)) {
      theta_index_[v] = ndof_++;
      scale.push_back(1.0 / r);
    }
    node_count_[v] = ndof_ - node_first_[v];
  }
  scale_ = Eigen::Map<Eigen::VectorXd>(scale.data(), scale.size());
  arc_.assign(ne + 1, 0.0);
  for (int e = 0; e < ne; ++e) arc_[e + 1] = arc_[e] + s_.rest_length[e];
}

BlockHessian StripProblem::make_hessian() const { return BlockHessian(node_first_, node_count_, ndof_); }

StripState StripProblem::initial_state() const {
  StripState st;
  st.x = s_.x;
  st.theta = s_.theta;
  st.twist = s_.ref_twist;
  st.frames.resize(s_.num_edges());
  for (int e = 0; e < s_.num_edges(); ++e)
    st.frames[e] = {(s_.x[s_.next(e)] - s_.x[e]).normalized(), s_.ref_d1[e]};
  st.certificate.dmin = contact_.dmin();
  st.certificate.min_distance = min_distance(st) * 2 * s_.radius;
  if (!(st.certificate.min_distance > st.certificate.dmin)) invalidate(st.certificate, "the generated strip has a pair within d_min");
  return st;
}

bool StripProblem::excluded(int a, int b) const {
  if (a == b) return true;
  if (a > b) std::swap(a, b);
  // Rest arc length strictly between the two edges, along the yarn (both ways when closed).
  double gap = arc_[b] - arc_[a + 1];
  if (s_.closed) gap = std::min(gap, arc_.back() - arc_[b + 1] + arc_[a]);
  return gap < opt_.exclusion_arc * s_.radius;
}

std::vector<std::pair<int, int>> StripProblem::contact_pairs(const StripState& st, double margin) const {
  const int ne = s_.num_edges();
  const double pad = 0.5 * (contact_.reach() + margin);
  std::vector<Box3> boxes(ne);
  for (int e = 0; e < ne; ++e) {
    const Eigen::Vector3d& a = st.x[e];
    const Eigen::Vector3d& b = st.x[s_.next(e)];
    boxes[e] = {a.cwiseMin(b).array() - pad, a.cwiseMax(b).array() + pad};
  }
  std::vector<std::pair<int, int>> pairs = overlapping_pairs(boxes);
  const double reach = contact_.reach() + margin;
  pairs.erase(std::remove_if(pairs.begin(), pairs.end(),
                             [&](const auto& p) {
                               if (excluded(p.first, p.second)) return true;
                               return segment_distance(st.x[p.first], st.x[s_.next(p.first)], st.x[p.second],
                                                       st.x[s_.next(p.second)]) >= reach;
                             }),
              pairs.end());
  return pairs;
}

namespace {

// Adds an element's local gradient (local coordinates: 3 per point, then the angles) to the
// reduced gradient; idx[k] is the reduced dof of local coordinate k, or -1.
template <int M>
void add_gradient(const int* idx, const Eigen::Matrix<double, M, 1>& g, Eigen::VectorXd* grad) {
  if (grad)
    for (int i = 0; i < M; ++i)
      if (idx[i] >= 0) (*grad)[idx[i]] += g[i];
}

}  // namespace

// What one evaluation computes: the contact pairs, which derivatives, and which Hessians (the
// exact or projected one in hess, the projected one's corrections in projected).
struct StripProblem::Assembly {
  std::vector<std::pair<int, int>> pairs;
  bool derivs = false, vertex_grad = false, project = false, project_boundary = false;
  BlockHessian* hess = nullptr;
  BlockHessian* projected = nullptr;
};

// One thread's sums (reduced in thread order afterwards); G points at g when a gradient is
// wanted.
struct StripProblem::Sums {
  EnergyParts e;
  Eigen::VectorXd g;
  std::vector<double> h, hp;
  std::vector<Eigen::Vector3d> vg;
  Eigen::VectorXd* G = nullptr;
  bool parts = false;
};

namespace {

void position_indices(const std::vector<int>& pos_index, int v, int* idx) {
  const int p = pos_index[v];
  for (int c = 0; c < 3; ++c) idx[c] = p < 0 ? -1 : p + c;
}

// Adds an element's Hessian H (exact or projected, as the model asks) and, for the projected
// Hessian assembled alongside, the correction of its projection when it is not convex (most
// elements are convex: one add per element, not two).
template <int M>
void add_hessian(BlockHessian* hess, BlockHessian* projected, const int* idx, const Eigen::Matrix<double, M, M>& H,
                 std::vector<double>& h, std::vector<double>& hp) {
  if (hess) hess->add<M>(idx, H, h);
  if (projected) {
    Eigen::Matrix<double, M, M> Hp = H;
    if (numerics::project_psd<M>(Hp)) projected->add<M>(idx, Eigen::Matrix<double, M, M>(Hp - H), hp);
  }
}

}  // namespace

// The pattern: the nodes every element couples (node = vertex).
void StripProblem::set_hessian_pattern(const std::vector<std::pair<int, int>>& pairs, BlockHessian* hess,
                                       BlockHessian* projected) const {
  const int n = s_.size(), ne = s_.num_edges();
  std::vector<std::pair<int, int>> np;
  np.reserve(3 * size_t(n) + 6 * pairs.size());
  for (int e = 0; e < ne; ++e) np.emplace_back(s_.next(e), e);
  for (int v = 0; v < n; ++v)
    if (s_.has_joint(v)) np.emplace_back(s_.next(v), s_.prev(v));
  for (const auto& [a, b] : pairs) {
    const int vs[4] = {a, s_.next(a), b, s_.next(b)};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < i; ++j) np.emplace_back(vs[i], vs[j]);
  }
  if (projected) projected->set_pattern(np);
  hess->set_pattern(std::move(np));
}

void StripProblem::stretch_sums(const StripState& st, const Assembly& A, Sums& L) const {
  const int ne = s_.num_edges();
  BlockHessian* hess = A.hess;
#pragma omp for schedule(static) nowait
  for (int ed = 0; ed < ne; ++ed) {
    const int v0 = ed, v1 = s_.next(ed);
    const double EA = s_.connector_edge[ed] ? EA_ * s_.connector_scale : EA_;
    Vec6 g;
    Mat6 H;
    L.e.stretch += stretch_energy(st.x[v0], st.x[v1], s_.rest_length[ed], EA, A.derivs ? &g : nullptr, hess ? &H : nullptr);
    if (!A.derivs) continue;
    if (hess && A.project) numerics::project_psd<6>(H);  // indefinite under compression
    int idx[6];
    position_indices(pos_index_, v0, idx);
    position_indices(pos_index_, v1, idx + 3);
    add_gradient<6>(idx, g, L.G);
    add_hessian<6>(hess, A.projected, idx, H, L.h, L.hp);
    if (A.vertex_grad) {
      L.vg[v0] += g.segment<3>(0);
      L.vg[v1] += g.segment<3>(3);
    }
  }
}

void StripProblem::joint_sums(const StripState& st, const Assembly& A, Sums& L) const {
  const int n = s_.size();
  BlockHessian* hess = A.hess;
#pragma omp for schedule(static) nowait
  for (int v = 0; v < n; ++v) {
    if (!s_.has_joint(v)) continue;
    const int a = s_.prev(v), b = s_.next(v);  // vertices; edges a (in) and v (out)
    const double k = s_.connector_joint[v] ? s_.connector_scale : 1.0;
    Vec11 q;
    q << st.x[a], st.x[v], st.x[b], st.theta[a], st.theta[v];
    const JointFrames f{st.frames[a], st.frames[v], st.twist[v]};
    const JointRest rest{s_.rest_kappa[v], s_.rest_twist[v], 0.5 * (s_.rest_length[a] + s_.rest_length[v])};
    if (L.parts) {
      L.e.bend += joint_energy(q, f, rest, k * EI_, k * GJ_, kBend, nullptr, nullptr);
      L.e.twist += joint_energy(q, f, rest, k * EI_, k * GJ_, kTwist, nullptr, nullptr);
    } else if (!A.derivs) {
      L.e.bend += joint_energy(q, f, rest, k * EI_, k * GJ_, kBendTwist, nullptr, nullptr);  // the trials' energies
    }
    if (!A.derivs) continue;
    Vec11 g;
    Mat11 H;
    const double ej = joint_energy(q, f, rest, k * EI_, k * GJ_, kBendTwist, &g, hess ? &H : nullptr);
    if (!L.parts) L.e.bend += ej;
    if (hess && (A.project || (A.project_boundary && s_.connector_joint[v]))) numerics::project_psd<11>(H);
    int idx[11];
    position_indices(pos_index_, a, idx);
    position_indices(pos_index_, v, idx + 3);
    position_indices(pos_index_, b, idx + 6);
    idx[9] = theta_index_[a];
    idx[10] = theta_index_[v];
    add_gradient<11>(idx, g, L.G);
    add_hessian<11>(hess, A.projected, idx, H, L.h, L.hp);
    if (A.vertex_grad)
      for (int c = 0; c < 3; ++c) L.vg[c == 0 ? a : c == 1 ? v : b] += g.segment<3>(3 * c);
  }
}

void StripProblem::contact_sums(const StripState& st, const Assembly& A, Sums& L) const {
  BlockHessian* hess = A.hess;
#pragma omp for schedule(static) nowait
  for (int i = 0; i < static_cast<int>(A.pairs.size()); ++i) {
    const int ea = A.pairs[i].first, eb = A.pairs[i].second;
    const int vs[4] = {ea, s_.next(ea), eb, s_.next(eb)};
    Vec12 q;
    q << st.x[vs[0]], st.x[vs[1]], st.x[vs[2]], st.x[vs[3]];
    Vec12 g;
    Mat12 H;
    const StripContact::Energy ec =
        contact_.energy(q, s_.rest_length[ea], s_.rest_length[eb], A.derivs ? &g : nullptr, hess ? &H : nullptr);
    L.e.contact += ec.kernel;
    L.e.barrier += ec.barrier;
    if (!A.derivs) continue;
    if (hess && A.project && ec.total() > 0) numerics::project_psd<12>(H);
    int idx[12];
    for (int c = 0; c < 4; ++c) position_indices(pos_index_, vs[c], idx + 3 * c);
    add_gradient<12>(idx, g, L.G);
    add_hessian<12>(hess, ec.total() > 0 ? A.projected : nullptr, idx, H, L.h, L.hp);
    if (A.vertex_grad)
      for (int c = 0; c < 4; ++c) L.vg[vs[c]] += g.segment<3>(3 * c);
  }
}

double StripProblem::evaluate(const StripState& st, Eigen::VectorXd* grad, BlockHessian* hess, EnergyParts* parts,
                              std::vector<Eigen::Vector3d>* vertex_grad, Projection projection,
                              BlockHessian* projected) const {
  if (!hess) projected = nullptr;
  const int n = s_.size();
  Assembly A;
  A.derivs = grad || hess || vertex_grad;
  A.vertex_grad = vertex_grad != nullptr;
  A.project = projection == Projection::kAll;
  A.project_boundary = projection == Projection::kBoundaryJoints;
  A.hess = hess;
  A.projected = projected;
  A.pairs = contact_pairs(st, hess ? opt_.hessian_margin * s_.radius : 0.0);
  if (hess) set_hessian_pattern(A.pairs, hess, projected);

  // The three sums in parallel for large strips; each thread keeps its own sums, reduced in
  // thread order (a static schedule: the same result bit for bit at a given thread count).
  const bool par = n >= 150 && !omp_in_parallel() && omp_get_max_threads() > 1;
  const int nthreads = par ? omp_get_max_threads() : 1;
  std::vector<Sums> local(nthreads);
#pragma omp parallel num_threads(nthreads) if (par)
  {
    Sums& L = local[par ? omp_get_thread_num() : 0];
    if (grad) L.g.setZero(ndof_);
    if (vertex_grad) L.vg.assign(n, Eigen::Vector3d::Zero());
    if (hess) hess->zero(L.h);
    if (projected) projected->zero(L.hp);
    L.G = grad ? &L.g : nullptr;
    L.parts = parts != nullptr;
    stretch_sums(st, A, L);
    joint_sums(st, A, L);
    contact_sums(st, A, L);
  }
  EnergyParts e;
  if (grad) grad->setZero(ndof_);
  if (vertex_grad) vertex_grad->assign(n, Eigen::Vector3d::Zero());
  for (const Sums& L : local) {
    e += L.e;
    if (grad) *grad += L.g;
    if (vertex_grad)
      for (int v = 0; v < n; ++v) (*vertex_grad)[v] += L.vg[v];
  }
  if (hess) {
    std::vector<std::vector<double>> hv(nthreads);
    for (int t = 0; t < nthreads; ++t) hv[t] = std::move(local[t].h);
    hess->gather(hv);
    if (projected) {
      for (int t = 0; t < nthreads; ++t) hv[t] = std::move(local[t].hp);
      projected->gather(hv, hess);
    }
  }
  if (parts) *parts = e;
  return e.total();
}

void StripProblem::apply_step(const Eigen::VectorXd& dy, double alpha, StripState& st) const {
  for (int v = 0; v < s_.size(); ++v)
    if (pos_index_[v] >= 0) st.x[v] += alpha * dy.segment<3>(pos_index_[v]);
  for (int e = 0; e < s_.num_edges(); ++e)
    if (theta_index_[e] >= 0) st.theta[e] += alpha * dy[theta_index_[e]];
}

double StripProblem::step_bound(const StripState& st, const Eigen::VectorXd& dy) const {
  std::vector<Eigen::Vector3d> to = st.x;
  for (int v = 0; v < s_.size(); ++v)
    if (pos_index_[v] >= 0) to[v] += dy.segment<3>(pos_index_[v]);
  return safe_fraction(st.x, to);
}

double StripProblem::safe_fraction(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) const {
  const int ne = s_.num_edges();
  // Only segments whose swept boxes come within d_min of each other can meet during the move.
  const double pad = 0.5 * contact_.dmin();
  std::vector<Box3> boxes(ne);
  for (int e = 0; e < ne; ++e) {
    const int w = s_.next(e);
    const Eigen::Vector3d lo = from[e].cwiseMin(from[w]).cwiseMin(to[e]).cwiseMin(to[w]);
    const Eigen::Vector3d hi = from[e].cwiseMax(from[w]).cwiseMax(to[e]).cwiseMax(to[w]);
    boxes[e] = {lo.array() - pad, hi.array() + pad};
  }
  const std::vector<std::pair<int, int>> pairs = overlapping_pairs(boxes);
  double t = 1.0;
#pragma omp parallel for schedule(dynamic, 64) reduction(min : t) if (pairs.size() > 2000 && !omp_in_parallel())
  for (int i = 0; i < static_cast<int>(pairs.size()); ++i) {
    const auto [ea, eb] = pairs[i];
    if (excluded(ea, eb)) continue;
    const int vs[4] = {ea, s_.next(ea), eb, s_.next(eb)};
    Vec12 q0, q1;
    for (int c = 0; c < 4; ++c) {
      q0.segment<3>(3 * c) = from[vs[c]];
      q1.segment<3>(3 * c) = to[vs[c]];
    }
    t = std::min(t, contact_.safe_fraction(q0, q1));
  }
  return t;
}

double StripProblem::min_distance(const StripState& st) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [ea, eb] : contact_pairs(st, 0.0))
    best = std::min(best, segment_distance(st.x[ea], st.x[s_.next(ea)], st.x[eb], st.x[s_.next(eb)]) / (2.0 * s_.radius));
  return best;
}

namespace {

// The reference frames parallel transported to the current tangents, and the joints' reference
// twists updated to them (what rebase_frames commits everywhere and track_frames where a
// tangent turned far).
std::vector<EdgeFrame> transported_frames(const Strip& s, StripState& st) {
  const int ne = s.num_edges();
  std::vector<EdgeFrame> now(ne);
  for (int e = 0; e < ne; ++e) {
    const Eigen::Vector3d t = (st.x[s.next(e)] - st.x[e]).normalized();
    now[e] = {t, transported_director(st.frames[e], t)};
  }
  for (int v = 0; v < s.size(); ++v) {
    if (!s.has_joint(v)) continue;
    const int a = s.prev(v);
    st.twist[v] = reference_twist(now[a].t, now[a].d1, now[v].t, now[v].d1, st.twist[v]);
  }
  return now;
}

}  // namespace

void StripProblem::rebase_frames(StripState& st) const { st.frames = transported_frames(s_, st); }

void StripProblem::track_frames(StripState& st, double max_turn) const {
  const double c = std::cos(max_turn);
  const std::vector<EdgeFrame> now = transported_frames(s_, st);
  for (size_t e = 0; e < now.size(); ++e)
    if (now[e].t.dot(st.frames[e].t) < c) st.frames[e] = now[e];
}

}  // namespace yarnhom::yarn
