#include "yarn/rve/rve.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include <omp.h>

#include "yarn/rod/frames.hpp"
#include "yarn/rve/rve_ccd.hpp"

namespace yarnhom::yarn {

Eigen::VectorXd RveState::packed() const {
  const int n = static_cast<int>(u.size());
  Eigen::VectorXd q(4 * n);
  for (int v = 0; v < n; ++v) {
    q.segment<3>(4 * v) = u[v];
    q[4 * v + 3] = theta[v];
  }
  return q;
}

struct RveProblem::Node {
  Eigen::Vector3d x;
  Eigen::Matrix3d J;                 // dx / d(reduced dofs of the vertex), first npos columns
  Eigen::Matrix3d R;                 // local mid-surface frame at the vertex's reference point
  Eigen::Matrix<double, 3, 6> dxds;  // dx / ds at fixed u (only when asked)
  Eigen::Matrix<double, 3, 6> omega; // dR/ds_k = [omega_k]x R (only when asked)
};

RveProblem::RveProblem(Pattern pattern, Material material, RveOptions options, const Eigen::Matrix2d& reference)
    : p_(std::move(pattern)), m_(material), opt_(options), F0_(reference) {
  const int n = p_.size();
  if (n < 2 || static_cast<int>(p_.rest_length.size()) != n)
    throw std::invalid_argument("RVE: pattern '" + p_.name + "' is incomplete (no rest state)");
  if (!F0_.allFinite() || F0_(1, 0) != 0.0 || !(F0_(0, 0) > 0 && F0_(1, 1) > 0))
    throw std::invalid_argument("RVE: the reference map of pattern '" + p_.name +
                                "' must be upper triangular with a positive diagonal");
  topo_ = topology(p_);
  const double r = p_.radius;
  EA_ = m_.young * M_PI * r * r;
  EI_ = m_.young * M_PI * r * r * r * r / 4.0;
  GJ_ = m_.shear * M_PI * r * r * r * r / 2.0;
  contact_ = {r, m_.contact_stiffness * r, opt_.contact_quadrature};
  if (!(opt_.barrier_dmin > 0 && opt_.barrier_dhat > opt_.barrier_dmin && opt_.barrier_dhat <= 1.0 &&
        opt_.barrier_stiffness > 0))
    throw std::invalid_argument("RVE: barrier needs 0 < d_min < d_hat <= 2r (in diameters) and a positive stiffness");
  barrier_ = {opt_.barrier_dmin * 2 * r, opt_.barrier_dhat * 2 * r, opt_.barrier_stiffness * contact_.kc * 4 * r * r};

  // Zero modes (docs/rve.md): the whole RVE's translation (pin every component of the first
  // vertex of yarn 0: this also stops yarn 0 sliding along itself); every other yarn's sliding
  // along itself (pin the tangential component of its first vertex; optional); the uniform
  // rotation of all twist angles of a yarn whose rest curvatures all vanish (pin one angle).
  npos_.assign(n, 3);
  basis_.assign(n, Eigen::Matrix3d::Identity());
  pinned_vertex_ = topo_.yarns[0][0];
  // Its in-plane components are pinned; its normal component is not an unknown but follows
  // from the others: the yarns' mean height over the mid-surface stays where the pattern put
  // it (docs/rve.md section 4). Under curvature a pin on the normal component fixed the height
  // of one point only, and the rest of the tile slid through the thickness towards the centre
  // of curvature, where the stretched yarns are shorter: on the paper's basket at s_x = 0.3,
  // II_x = 100 /m the yarns' mean height moved 1.4 mm (a yarn radius and more), Psi fell from
  // 2.47 to 2.20 J/m^2 and the flat stretched tile became a maximum in bending, which a
  // continuum strip then wrinkled on. One slot beyond the unknowns carries it during assembly.
  npos_[pinned_vertex_] = 1;
  basis_[pinned_vertex_].setZero();
  basis_[pinned_vertex_](2, 0) = 1.0;
  // The yarn's direction in the reference tile (the stored edges mapped by F0).
  Eigen::Matrix3d F03 = Eigen::Matrix3d::Identity();
  F03.topLeftCorner<2, 2>() = F0_;
  for (size_t y = 1; y < topo_.yarns.size() && m_.slide_constraint; ++y) {
    const int v = topo_.yarns[y][0];
    const Eigen::Vector3d t = ((F03 * stored_edge(p_, topo_, topo_.prev[v])).normalized() +
                               (F03 * stored_edge(p_, topo_, v)).normalized())
                                  .normalized();
    // Two unit vectors perpendicular to the yarn: the vertex may move across, not along it.
    Eigen::Vector3d a = std::abs(t[2]) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d b1 = (a - a.dot(t) * t).normalized(), b2 = t.cross(b1);
    basis_[v].setZero();
    basis_[v].col(0) = b1;
    basis_[v].col(1) = b2;
    npos_[v] = 2;
    slide_pinned_.push_back(v);
  }
  theta_index_.assign(n, -1);
  std::vector<bool> theta_free(n, true);
  for (const auto& yarn : topo_.yarns) {
    bool straight = true;
    for (int v : yarn) straight = straight && p_.rest_kappa[v].isZero(0.0);
    if (straight) {
      theta_free[yarn[0]] = false;
      twist_pinned_.push_back(yarn[0]);
    }
  }
  pos_index_.assign(n, -1);
  std::vector<double> scale;
  for (int v = 0; v < n; ++v) {
    if (v != pinned_vertex_) {
      pos_index_[v] = ndof_;
      for (int c = 0; c < npos_[v]; ++c) scale.push_back(1.0);
      ndof_ += npos_[v];
    }
    if (theta_free[v]) {
      theta_index_[v] = ndof_++;
      scale.push_back(1.0 / r);
    }
  }
  scale_ = Eigen::Map<Eigen::VectorXd>(scale.data(), scale.size());
  pos_index_[pinned_vertex_] = ndof_;  // the dependent slot, removed at the end of evaluate()
  // sum_v w_v u_v,n = 0 with w_v the vertex's share of yarn length: u_p,n = height_coef_ . y.
  height_weight_.resize(n);
  for (int v = 0; v < n; ++v) height_weight_[v] = 0.5 * (p_.rest_length[topo_.prev[v]] + p_.rest_length[v]);
  height_coef_.setZero(ndof_);
  for (int v = 0; v < n; ++v)
    if (v != pinned_vertex_)
      for (int c = 0; c < npos_[v]; ++c)
        height_coef_[pos_index_[v] + c] = -height_weight_[v] / height_weight_[pinned_vertex_] * basis_[v](2, c);

  // Same-yarn segment pairs too close along the yarn to touch without bending sharper than the
  // yarn's own radius (rest arc gap below exclusion_arc * r), with the tile offset at which
  // the later one lies.
  for (int v = 0; v < n; ++v) {
    const int len = static_cast<int>(topo_.yarns[topo_.yarn_of[v]].size());
    Eigen::Vector2i o = topo_.offset[v];
    double gap = 0;
    int w = topo_.next[v];
    for (int j = 1; j <= len && gap < opt_.exclusion_arc * r; ++j) {
      if (!(w == v && o.isZero())) excluded_.insert(pair_key(v, w, o));
      gap += p_.rest_length[w];
      o += topo_.offset[w];
      w = topo_.next[w];
    }
  }
}

Eigen::Matrix2d RveProblem::lattice() const {
  return F0_ * Eigen::Vector2d(p_.px, p_.py).asDiagonal();
}

Strain RveProblem::pattern_strain() const {
  // F0^-1 = [[a, b], [0, c]]: its columns are the deformed axes of F(s).
  const Eigen::Matrix2d M = F0_.inverse();
  const double a = M.col(0).norm(), c = M.col(1).norm();
  Strain s = Strain::Zero();
  s << a - 1, M.col(0).dot(M.col(1)) / (a * c), c - 1, 0, 0, 0;
  if (F0_.isIdentity(0.0)) s.setZero();  // exactly, not to round-off
  return s;
}

RveState RveProblem::initial_state(bool record_path) const {
  const int n = p_.size();
  RveState st;
  st.u.assign(n, Eigen::Vector3d::Zero());
  st.anchor = {pattern_strain(), st.u};
  if (record_path) st.path = {st.anchor};
  st.certificate.dmin = barrier_.dmin;
  st.certificate.min_distance = yarn::min_separation(*this, st.anchor.s, st, 2 * p_.radius);
  if (!(st.certificate.min_distance > barrier_.dmin))
    invalidate(st.certificate, "the pattern's own geometry has yarn segments closer than d_min");
  st.theta = p_.theta;
  st.frames.edge.resize(n);
  st.frames.twist.resize(n);
  // The stored frames, carried into the reference tile: tangents of the edges mapped by F0,
  // directors parallel transported to them (nothing changes when F0 = I).
  Eigen::Matrix3d F03 = Eigen::Matrix3d::Identity();
  F03.topLeftCorner<2, 2>() = F0_;
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d t0 = stored_edge(p_, topo_, v).normalized();
    Eigen::Vector3d d = p_.ref_d1[v] - p_.ref_d1[v].dot(t0) * t0;  // the file's are rounded
    const Eigen::Vector3d t = (F03 * t0).normalized();
    const V3<double> dt = transport_same(V3<double>(t0), V3<double>(t), V3<double>(d.normalized()));
    d = Eigen::Vector3d(dt.x, dt.y, dt.z);
    st.frames.edge[v] = {t, (d - d.dot(t) * t).normalized()};
  }
  for (int v = 0; v < n; ++v) {
    const int a = topo_.prev[v];
    st.frames.twist[v] = reference_twist(st.frames.edge[a].t, st.frames.edge[a].d1,
                                         st.frames.edge[v].t, st.frames.edge[v].d1, p_.ref_twist[v]);
  }
  return st;
}

ShellPoint<double> RveProblem::shell_point(const Strain& s, int v, Eigen::Vector2i o) const {
  // The reference point: the stored in-plane position (plus the image's period) mapped by F0.
  const Eigen::Vector2d xi = F0_ * Eigen::Vector2d(p_.x[v][0] + o[0] * p_.px, p_.x[v][1] + o[1] * p_.py);
  return shell_map(s.data(), xi[0], xi[1], p_.x[v][2]);
}

RveProblem::Node RveProblem::node(const Strain& s, const RveState& st, int v, Eigen::Vector2i o,
                                  bool want_ds) const {
  const Eigen::Vector2d xi = F0_ * Eigen::Vector2d(p_.x[v][0] + o[0] * p_.px, p_.x[v][1] + o[1] * p_.py);
  const double xi1 = xi[0], xi2 = xi[1], h = p_.x[v][2];
  const ShellPoint<double> sp = shell_point(s, v, o);
  Node nd;
  const V3<double> x = sp.apply(st.u[v]);
  nd.x = Eigen::Vector3d(x.x, x.y, x.z);
  Eigen::Matrix3d R;
  for (int c = 0; c < 3; ++c) R.col(c) = Eigen::Vector3d(sp.R[c].x, sp.R[c].y, sp.R[c].z);
  nd.R = R;
  nd.J = R * basis_[v];
  if (want_ds) {
    Jet<6> sj[6];
    for (int k = 0; k < 6; ++k) sj[k] = Jet<6>::variable(k, s[k]);
    const ShellPoint<Jet<6>> spj = shell_map(sj, xi1, xi2, h);
    const V3<Jet<6>> xj = spj.apply(st.u[v]);
    nd.dxds.row(0) = xj.x.g.transpose();
    nd.dxds.row(1) = xj.y.g.transpose();
    nd.dxds.row(2) = xj.z.g.transpose();
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix3d dR;
      for (int c = 0; c < 3; ++c) dR.col(c) << spj.R[c].x.g[k], spj.R[c].y.g[k], spj.R[c].z.g[k];
      const Eigen::Matrix3d W = dR * R.transpose();  // skew for a rotation family
      nd.omega.col(k) << 0.5 * (W(2, 1) - W(1, 2)), 0.5 * (W(0, 2) - W(2, 0)), 0.5 * (W(1, 0) - W(0, 1));
    }
  }
  return nd;
}

Eigen::Vector3d RveProblem::position(const Strain& s, const RveState& st, int v, Eigen::Vector2i o) const {
  return node(s, st, v, o, false).x;
}

std::vector<Eigen::Vector3d> RveProblem::positions(const Strain& s, const RveState& st) const {
  std::vector<Eigen::Vector3d> x(p_.size());
  for (int v = 0; v < p_.size(); ++v) x[v] = position(s, st, v, Eigen::Vector2i::Zero());
  return x;
}

template <int M>
void RveProblem::scatter(int nslots, const Node* const* nodes, const int* verts, int nth,
                         const int* thv, const Eigen::Matrix<double, M, 1>& gl,
                         const Eigen::Matrix<double, M, M>* Hl, Eigen::VectorXd* grad,
                         std::vector<Eigen::Triplet<double>>* hess, Strain* dEds) const {
  if (dEds)
    for (int a = 0; a < nslots; ++a) *dEds += nodes[a]->dxds.transpose() * gl.template segment<3>(3 * a);
  if (!grad && !hess) return;
  // P maps the reduced dofs this element touches to its local coordinates.
  int idx[M];
  Eigen::Matrix<double, M, M> P = Eigen::Matrix<double, M, M>::Zero();
  int k = 0;
  for (int a = 0; a < nslots; ++a) {
    const int v = verts[a];
    for (int c = 0; c < npos_[v]; ++c, ++k) {
      idx[k] = pos_index_[v] + c;
      P.template block<3, 1>(3 * a, k) = nodes[a]->J.col(c);
    }
  }
  for (int j = 0; j < nth; ++j) {
    const int ti = theta_index_[thv[j]];
    if (ti < 0) continue;
    idx[k] = ti;
    P(3 * nslots + j, k) = 1.0;
    ++k;
  }
  if (grad) {
    const Eigen::Matrix<double, M, 1> gr = P.transpose() * gl;
    for (int i = 0; i < k; ++i) (*grad)[idx[i]] += gr[i];
  }
  if (hess && Hl) {
    const Eigen::Matrix<double, M, M> Hr = P.transpose() * (*Hl) * P;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j)
        if (idx[i] >= idx[j]) hess->emplace_back(idx[i], idx[j], Hr(i, j));  // lower triangle
  }
}

// One evaluation's points, computed once each: the base tile, each vertex's neighbours along its
// yarn, and the images that contact pairs use; the contact pairs.
struct RveProblem::Assembly {
  const RveState* st = nullptr;
  bool derivs = false, hessian = false, parts = false, ds = false;
  std::vector<Node> base, nxt, prv;
  std::unordered_map<uint64_t, Node> images;
  std::vector<Pair> pairs;
  std::vector<const Node*> pb0, pb1;  // per pair: its second segment's ends (element pointers stay valid)
};

// One thread's sums (reduced in thread order afterwards); G, T, D point at them when wanted.
struct RveProblem::Sums {
  EnergyParts e;
  Eigen::VectorXd g;
  std::vector<Eigen::Triplet<double>> trip;
  Strain d = Strain::Zero();
  Eigen::VectorXd* G = nullptr;
  std::vector<Eigen::Triplet<double>>* T = nullptr;
  Strain* D = nullptr;
};

void RveProblem::prepare(const Strain& s, const RveState& st, Assembly& A) const {
  const int n = p_.size();
  const bool ds = A.ds;
  A.st = &st;
  A.base.resize(n);
  A.nxt.resize(n);
  A.prv.resize(n);
  // A neighbour inside the tile is a base point already (node() gives the same bits again);
  // only those across the tile's border are mapped anew.
  for (int v = 0; v < n; ++v) A.base[v] = node(s, st, v, Eigen::Vector2i::Zero(), ds);
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector2i on = topo_.offset[v], op = -topo_.offset[topo_.prev[v]];
    A.nxt[v] = on.isZero() ? A.base[topo_.next[v]] : node(s, st, topo_.next[v], on, ds);
    A.prv[v] = op.isZero() ? A.base[topo_.prev[v]] : node(s, st, topo_.prev[v], op, ds);
  }
  auto image = [&](int v, Eigen::Vector2i o) -> const Node& {
    if (o.isZero()) return A.base[v];
    const uint64_t key = (uint64_t(v) << 16) | (uint64_t(o[0] + 128) << 8) | uint64_t(o[1] + 128);
    auto it = A.images.find(key);
    if (it == A.images.end()) it = A.images.emplace(key, node(s, st, v, o, ds)).first;
    return it->second;
  };
  // With a Hessian, pairs slightly beyond reach keep (zero) entries: a stable pattern.
  const double margin = A.hessian ? opt_.hessian_margin * p_.radius : 0.0;
  A.pairs = contact_pairs(s, st, margin);
  A.pb0.resize(A.pairs.size());
  A.pb1.resize(A.pairs.size());
  for (size_t i = 0; i < A.pairs.size(); ++i) {
    const Pair& pr = A.pairs[i];
    A.pb0[i] = &image(pr.b, pr.o);
    A.pb1[i] = &image(topo_.next[pr.b], pr.o + topo_.offset[pr.b]);
  }
}

namespace {
// The first item of chunk c of `chunks` equal ranges over n items.
int chunk_begin(int n, int c, int chunks) { return static_cast<int>(static_cast<long long>(n) * c / chunks); }
}  // namespace

// Stretch, per edge (the vertex's outgoing edge).
void RveProblem::stretch_sums(const Assembly& A, Sums& L, int chunk, int chunks) const {
  const int n = p_.size();
  for (int v = chunk_begin(n, chunk, chunks); v < chunk_begin(n, chunk + 1, chunks); ++v) {
    const int w = topo_.next[v];
    const Node& nw = A.nxt[v];
    Vec6 g;
    Mat6 H;
    L.e.stretch += stretch_energy(A.base[v].x, nw.x, p_.rest_length[v], EA_, A.derivs ? &g : nullptr,
                                  A.hessian ? &H : nullptr);
    if (A.derivs) {
      const Node* nodes[2] = {&A.base[v], &nw};
      const int verts[2] = {v, w};
      scatter<6>(2, nodes, verts, 0, nullptr, g, A.hessian ? &H : nullptr, L.G, L.T, L.D);
    }
  }
}

// Bend and twist, per joint.
void RveProblem::joint_sums(const Assembly& A, Sums& L, int chunk, int chunks) const {
  const int n = p_.size();
  const RveState& st = *A.st;
  for (int v = chunk_begin(n, chunk, chunks); v < chunk_begin(n, chunk + 1, chunks); ++v) {
    const int a = topo_.prev[v], b = topo_.next[v];
    const Node& na = A.prv[v];
    const Node& nb = A.nxt[v];
    Vec11 q;
    q << na.x, A.base[v].x, nb.x, st.theta[a], st.theta[v];
    // The stored frames are rest-state (s = 0) vectors; each joint carries them with its own
    // local mid-surface frame R_v before transporting them to the current tangents. That
    // makes the directors periodic in the local frame, like the fluctuations: an edge that
    // crosses the tile boundary is seen at two images with different tangents under
    // curvature, and each joint turns the stored frame to its own image (docs/rve.md).
    const Eigen::Matrix3d& Rv = A.base[v].R;
    const JointFrames f{{Rv * st.frames.edge[a].t, Rv * st.frames.edge[a].d1},
                        {Rv * st.frames.edge[v].t, Rv * st.frames.edge[v].d1},
                        st.frames.twist[v]};
    const JointRest rest{p_.rest_kappa[v], p_.rest_twist[v], 0.5 * (p_.rest_length[a] + p_.rest_length[v])};
    if (A.parts || !A.derivs) {
      L.e.bend += joint_energy(q, f, rest, EI_, GJ_, kBend, nullptr, nullptr);
      L.e.twist += joint_energy(q, f, rest, EI_, GJ_, kTwist, nullptr, nullptr);
    }
    if (!A.derivs) continue;
    Vec11 g;
    Mat11 H;
    const double ej = joint_energy(q, f, rest, EI_, GJ_, kBendTwist, &g, A.hessian ? &H : nullptr);
    if (!A.parts) L.e.bend += ej;
    const Node* nodes[3] = {&na, &A.base[v], &nb};
    const int verts[3] = {a, v, b};
    const int thv[2] = {a, v};
    scatter<11>(3, nodes, verts, 2, thv, g, A.hessian ? &H : nullptr, L.G, L.T, L.D);
    if (L.D) {
      // The joint also depends on s through R_v. The joint energy is invariant under a
      // rotation of its points and frames together, so turning the frames alone by a small
      // omega changes it by minus what turning the points does: -omega . sum (x_a x g_a).
      Eigen::Vector3d torque = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) torque += (q.segment<3>(3 * k) - A.base[v].x).cross(g.segment<3>(3 * k));
      *L.D -= A.base[v].omega.transpose() * torque;
    }
  }
}

// Contact: the kernel and the barrier on the pair's exact closest distance (zero beyond
// d_hat < 2r: most pairs stop at its distance test).
void RveProblem::contact_sums(const Assembly& A, Sums& L, int chunk, int chunks) const {
  const int np = static_cast<int>(A.pairs.size());
  for (int i = chunk_begin(np, chunk, chunks); i < chunk_begin(np, chunk + 1, chunks); ++i) {
    const Pair& pr = A.pairs[i];
    const int a1 = topo_.next[pr.a], b1 = topo_.next[pr.b];
    const Node& na1 = A.nxt[pr.a];
    const Node& nb0 = *A.pb0[i];
    const Node& nb1 = *A.pb1[i];
    Vec12 q;
    q << A.base[pr.a].x, na1.x, nb0.x, nb1.x;
    Vec12 g;
    Mat12 H;
    L.e.contact += segment_contact_energy(q, p_.rest_length[pr.a], p_.rest_length[pr.b], contact_,
                                          A.derivs ? &g : nullptr, A.hessian ? &H : nullptr);
    Vec12 gb;
    Mat12 Hb;
    const double eb = segment_barrier_energy(q, barrier_, A.derivs ? &gb : nullptr, A.hessian ? &Hb : nullptr);
    if (eb != 0) {
      L.e.barrier += eb;
      if (A.derivs) g += gb;
      if (A.hessian) H += Hb;
    }
    // A pair out of reach (a candidate of the broad phase only) adds exact zeros: skipped, so
    // that it costs no assembly and puts no entry in a sparse Hessian's pattern (sums without
    // its zeros are the same numbers).
    if (A.derivs && !(g.isZero(0.0) && (!A.hessian || H.isZero(0.0)))) {
      const Node* nodes[4] = {&A.base[pr.a], &na1, &nb0, &nb1};
      const int verts[4] = {pr.a, a1, pr.b, b1};
      scatter<12>(4, nodes, verts, 0, nullptr, g, A.hessian ? &H : nullptr, L.G, L.T, L.D);
    }
  }
}

double RveProblem::evaluate(const Strain& s, const RveState& st, Eigen::VectorXd* grad,
                            std::vector<Eigen::Triplet<double>>* hess, EnergyParts* parts,
                            Strain* dEds) const {
  return evaluate_all(s, st, grad, hess, parts, dEds, nullptr);
}

double RveProblem::evaluate_hessian(const Strain& s, const RveState& st, Eigen::VectorXd* grad,
                                    std::vector<Eigen::Triplet<double>>* hess, HeightTerm* height) const {
  if (!hess || !height) throw std::invalid_argument("evaluate_hessian: needs the triplets and the height term");
  return evaluate_all(s, st, grad, hess, nullptr, nullptr, height);
}

double RveProblem::evaluate_all(const Strain& s, const RveState& st, Eigen::VectorXd* grad,
                                std::vector<Eigen::Triplet<double>>* hess, EnergyParts* parts, Strain* dEds,
                                HeightTerm* height) const {
  const int n = p_.size();
  if (grad) grad->setZero(ndof_ + 1);  // + the dependent height slot (constructor)
  if (dEds) dEds->setZero();
  const size_t hess_start = hess ? hess->size() : 0;
  Assembly A;
  A.derivs = grad || hess || dEds;
  A.hessian = hess != nullptr;
  A.parts = parts != nullptr;
  A.ds = dEds != nullptr;
  // Contact pairs and the images they use, found serially; then the three sums in a fixed
  // number of chunks (8 for large patterns, one for small ones), each chunk a fixed range of
  // edges, joints and pairs with its own sums, added in chunk order afterwards. The chunks, not
  // the threads, decide the order of the additions, so the result is the same bit for bit at
  // any thread count: a produce run on MPI ranks of one thread each writes the dataset of a
  // many-thread run (docs/produce.md). The chunks run in parallel only outside the producer's
  // own parallel sectors.
  prepare(s, st, A);
  const int chunks = n >= 150 ? 8 : 1;
  const bool par = chunks > 1 && !omp_in_parallel() && omp_get_max_threads() > 1;
  std::vector<Sums> local(chunks);
#pragma omp parallel for schedule(static, 1) num_threads(std::min(chunks, omp_get_max_threads())) if (par)
  for (int c = 0; c < chunks; ++c) {
    Sums& L = local[c];
    if (grad) L.g.setZero(ndof_ + 1);
    L.G = grad ? &L.g : nullptr;
    L.T = hess ? &L.trip : nullptr;
    L.D = dEds ? &L.d : nullptr;
    stretch_sums(A, L, c, chunks);
    joint_sums(A, L, c, chunks);
    contact_sums(A, L, c, chunks);
  }
  EnergyParts e;
  for (const Sums& L : local) {
    e += L.e;
    if (grad) *grad += L.g;
    if (hess) hess->insert(hess->end(), L.trip.begin(), L.trip.end());
    if (dEds) *dEds += L.d;
  }
  if (parts) *parts = e;
  eliminate_height(grad, hess, hess_start, height);
  return e.total();
}

// The dependent slot d (the pinned vertex's height) is u_d = a . y with a = height_coef_, so by
// the chain rule g_y += g_d a and H_yy += a h^T + h a^T + H_dd a a^T with h = H_yd: a dense
// rank-2 term over the height unknowns (one per vertex; the RVE's Hessian is factored densely
// up to the paper's tile sizes, numerics/hessian_factor.hpp). It keeps a projected Hessian PSD.
// With `height` the term is returned there as U C U^T (HeightTerm in rve.hpp) instead.
void RveProblem::eliminate_height(Eigen::VectorXd* grad, std::vector<Eigen::Triplet<double>>* hess,
                                  size_t hess_start, HeightTerm* height) const {
  const int d = ndof_;
  const Eigen::VectorXd& a = height_coef_;
  if (grad) {
    grad->head(d) += (*grad)[d] * a;
    grad->conservativeResize(d);
  }
  if (!hess) return;
  Eigen::VectorXd h = Eigen::VectorXd::Zero(d);
  double Hdd = 0;
  size_t keep = hess_start;
  for (size_t i = hess_start; i < hess->size(); ++i) {
    const Eigen::Triplet<double>& t = (*hess)[i];
    if (t.row() == d && t.col() == d) Hdd += t.value();
    else if (t.row() == d) h[t.col()] += t.value();  // lower triangle: the slot is the last row
    else (*hess)[keep++] = t;
  }
  hess->resize(keep);
  if (height) {
    height->U.resize(d, 2);
    height->U.col(0) = a;
    height->U.col(1) = h;
    height->C << Hdd, 1, 1, 0;
    return;
  }
  std::vector<int> idx;
  for (int i = 0; i < d; ++i)
    if (a[i] != 0 || h[i] != 0) idx.push_back(i);
  for (size_t p = 0; p < idx.size(); ++p)
    for (size_t q = 0; q <= p; ++q) {
      const int i = idx[p], j = idx[q];
      const double v = a[i] * h[j] + h[i] * a[j] + Hdd * a[i] * a[j];
      if (v != 0) hess->emplace_back(i, j, v);
    }
}

void RveProblem::apply_step(const Eigen::VectorXd& dy, double alpha, RveState& st) const {
  for (int v = 0; v < p_.size(); ++v) {
    if (v != pinned_vertex_)
      for (int c = 0; c < npos_[v]; ++c) st.u[v] += alpha * dy[pos_index_[v] + c] * basis_[v].col(c);
    if (theta_index_[v] >= 0) st.theta[v] += alpha * dy[theta_index_[v]];
  }
  st.u[pinned_vertex_] = Eigen::Vector3d(0, 0, dependent_height(st));
}

double RveProblem::dependent_height(const RveState& st) const {
  double sum = 0;
  for (int v = 0; v < p_.size(); ++v)
    if (v != pinned_vertex_) sum += height_weight_[v] * st.u[v][2];
  return -sum / height_weight_[pinned_vertex_];
}

double RveProblem::mean_height(const RveState& st) const {
  double sum = 0, w = 0;
  for (int v = 0; v < p_.size(); ++v) sum += height_weight_[v] * st.u[v][2], w += height_weight_[v];
  return sum / w;
}

}  // namespace yarnhom::yarn
