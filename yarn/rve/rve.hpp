#pragma once
// The periodic yarn RVE under a macroscopic strain s (docs/rve.md): vertex positions are the
// shell map of s plus periodic fluctuations u in the local mid-surface frame, twist angles are
// unknowns too, and the energy is the discrete-elastic-rod energy of the closed yarns plus
// yarn-yarn contact across periodic images. This file evaluates the energy, its exact gradient
// and Hessian in the reduced unknowns (zero modes removed), and dE/ds at fixed unknowns.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "numerics/barrier.hpp"
#include "yarn/rod/contact.hpp"
#include "yarn/rod/contact_certificate.hpp"
#include "yarn/rod/energy_parts.hpp"
#include "yarn/rod/material.hpp"
#include "yarn/rod/pattern.hpp"
#include "yarn/rod/rod.hpp"
#include "yarn/rve/shell_map.hpp"

namespace yarnhom::yarn {

using numerics::BarrierParams;

// Reference frames of the discrete rods: each edge's director at its rest tangent (the
// pattern's *RefD1), turned by the local mid-surface frame R_v of the joint that uses it and
// parallel transported to the edge's current tangent there. They stay fixed during solves,
// which makes E(s, u, theta) one fixed smooth function: Psi(s) does not depend on the path a
// solve took, and the envelope theorem holds exactly. Re-basing the frames after each step,
// as time-stepping DER codes do, is NOT harmless here: under curvature the shell map is not
// periodic, an edge crossing the tile boundary has different tangents in the joints at its
// two ends (its two images), and a re-based frame changes the energy landscape (measured on
// stocktiny before this design: Psi moved by 1.6e-7 relative and the envelope gradient was
// off by 4e-4 relative to finite differences of Psi).
struct FrameState {
  std::vector<EdgeFrame> edge;  // per vertex (its outgoing edge)
  std::vector<double> twist;    // reference twist per joint (vertex)
};

// One configuration of the yarns: the strain and the fluctuations (positions do not depend on
// the twist angles). A path of them is what a topology certificate checks (yarn/rve/rve_ccd.hpp).
struct PathPoint {
  Strain s = Strain::Zero();
  std::vector<Eigen::Vector3d> u;
};

// Everything a solve starts from and ends with. Warm starting = passing the state of a
// neighbouring strain: u is relative to the local mid-surface frame, so keeping it is the
// solution migration of supplement Eq. 2; the reference directors are parallel transported
// to the current tangents inside every energy evaluation, which covers supplement Eq. 3.
struct RveState {
  std::vector<Eigen::Vector3d> u;  // per vertex, in the local frame (q1, q2, n), m
  std::vector<double> theta;       // per vertex: twist angle of its outgoing edge, rad
  FrameState frames;
  // The path that led to this state from the pattern's own geometry (docs/rve.md section 5):
  // what its collision checks found, and the last configuration they checked. A solve first
  // checks the straight move from `anchor` to its own start (s, u), so a state may be changed
  // between solves (a warm start's predictor) without the change going unchecked. `path`
  // holds every configuration of it when recording (initial_state(true)), else stays empty.
  ContactCertificate certificate;
  PathPoint anchor;
  std::vector<PathPoint> path;
  // [u^0, tau^0, u^1, tau^1, ...] as in supplement Eq. 1 (4 values per vertex).
  Eigen::VectorXd packed() const;
};

struct RveOptions {
  int contact_quadrature = 4;
  double exclusion_arc = M_PI;     // in yarn radii: same-yarn segments closer along the
                                   // yarn than this (rest arc length) never touch
  double hessian_margin = 0.5;     // in yarn radii: pairs this far beyond contact still get
                                   // (zero) Hessian entries, so the sparsity pattern is stable
  // The barrier on the closest distance of segment pairs (numerics/barrier.hpp, docs/rve.md
  // section 3), in yarn diameters 2r: +inf at barrier_dmin (no solve step reaches it: the
  // Newton solver's collision filter), zero beyond barrier_dhat; energy scale
  // barrier_stiffness * k_c (2r)^2. Physical equilibria keep their centrelines above
  // 0.62 x 2r (measured, docs/rve.md), so the barrier does not touch them.
  double barrier_dmin = 0.25;
  double barrier_dhat = 0.5;
  double barrier_stiffness = 1.0;
};

class RveProblem {
 public:
  // `reference` F0 (2x2, upper triangular, det > 0) maps the pattern's stored in-plane
  // coordinates to the reference tile in which s = 0 is measured: the mid-surface is
  //   phi(xi) = (F(s) F0 xi, 1/2 (F0 xi)^T II (F0 xi)),
  // so the tile's lattice vectors at s = 0 are F0 (px, 0) and F0 (0, py). Identity: the
  // pattern's own period (pre-stressed in general); the stress-free reference comes from
  // relax_tile (yarn/rve/rest.hpp, docs/rve.md section 6).
  RveProblem(Pattern pattern, Material material, RveOptions options = {},
             const Eigen::Matrix2d& reference = Eigen::Matrix2d::Identity());

  const Pattern& pattern() const { return p_; }
  const Topology& topo() const { return topo_; }
  const Material& material() const { return m_; }
  const RveOptions& options() const { return opt_; }
  const Eigen::Matrix2d& reference() const { return F0_; }
  // Lattice vectors of the reference tile (columns): F0 diag(px, py).
  Eigen::Matrix2d lattice() const;
  // Area of the reference tile, det(F0) px py: Psi is energy per unit of this area.
  double area() const { return F0_.determinant() * p_.px * p_.py; }
  int num_dofs() const { return ndof_; }
  double radius() const { return p_.radius; }
  double stretch_stiffness() const { return EA_; }

  // u = 0, theta, frames and reference twists from the pattern. Its anchor is the pattern's own
  // geometry (pattern_strain(), u = 0; with F0 = I that is s = 0), its certificate that
  // geometry's closest distance (valid if above d_min), and with record_path its path starts
  // there: the first solve checks the move from it to its start.
  RveState initial_state(bool record_path = false) const;

  // The strain at which this problem reproduces the pattern's own stored geometry with u = 0:
  // F(s) F0 = I, the in-plane strain of F0^-1 (zero when F0 = I). Every certified path starts
  // there (docs/rve.md section 5).
  Strain pattern_strain() const;

  // The barrier's parameters (m, J); min_separation() = its d_min, the separation that a
  // topology certificate checks (docs/rve.md section 5).
  const BarrierParams& barrier() const { return barrier_; }
  double min_separation() const { return barrier_.dmin; }

  // Energy at s; with grad: the gradient in the reduced unknowns; with hess: the lower
  // triangle (row >= col) of the symmetric Hessian as triplets (duplicates summed by the
  // caller's setFromTriplets); with dEds: dE/ds at fixed unknowns.
  double evaluate(const Strain& s, const RveState& st, Eigen::VectorXd* grad = nullptr,
                  std::vector<Eigen::Triplet<double>>* hess = nullptr, EnergyParts* parts = nullptr,
                  Strain* dEds = nullptr) const;

  // The Hessian's rank-2 term from the eliminated height unknown (see eliminate_height in
  // rve.cpp), kept apart: H = (the triplets) + U C U^T with U = [a h] (n x 2), C = [[H_dd, 1],
  // [1, 0]]. evaluate() appends it to the triplets, a dense block over every height unknown;
  // a sparse factorization keeps it out of the factor (numerics/hessian_factor.hpp).
  struct HeightTerm {
    Eigen::MatrixXd U;
    Eigen::Matrix2d C;
  };
  // evaluate() with the Hessian (hess required) in those two parts.
  double evaluate_hessian(const Strain& s, const RveState& st, Eigen::VectorXd* grad,
                          std::vector<Eigen::Triplet<double>>* hess, HeightTerm* height) const;

  // st += alpha * dy in the reduced unknowns.
  void apply_step(const Eigen::VectorXd& dy, double alpha, RveState& st) const;
  // Per reduced dof: 1 for positions, 1/r for twist angles (moments -> forces), for residuals.
  const Eigen::VectorXd& force_scale() const { return scale_; }

  // Deformed positions of the base tile's vertices, and of vertex v's image at tile offset o.
  std::vector<Eigen::Vector3d> positions(const Strain& s, const RveState& st) const;
  Eigen::Vector3d position(const Strain& s, const RveState& st, int v, Eigen::Vector2i o) const;
  // The map at vertex v's reference point in the image at offset o: x = Phi + R u for any u
  // (one evaluation serves several states at one strain).
  ShellPoint<double> shell_point(const Strain& s, int v, Eigen::Vector2i o) const;

  // Candidate contact pairs (segment a in the base tile, segment b at tile offset o) whose
  // inflated bounding boxes overlap, from a hash grid: never all pairs.
  struct Pair {
    int a, b;
    Eigen::Vector2i o;
  };
  std::vector<Pair> contact_pairs(const Strain& s, const RveState& st, double margin) const;
  bool excluded(int a, int b, Eigen::Vector2i o) const;
  // An in-plane box that holds every image of the tile at (s, st), segments' far ends included,
  // from the map alone (no shell map per vertex; rve_pairs.cpp): the broad phases skip images
  // out of reach before mapping them.
  struct ImageBound {
    Eigen::Vector2d lo, hi;  // the base tile's reference points mapped by F(s) F0
    Eigen::Matrix2d step;    // tile offset -> in-plane translation of the image
    double pad = 0;          // max |h| + |u| over the vertices, plus a round-off margin
    void image_box(Eigen::Vector2i o, Eigen::Vector2d& l, Eigen::Vector2d& h) const;  // padded
    // Whether the image at o (its box inflated by reach) may meet the box [lo3, hi3] in-plane.
    bool may_reach(Eigen::Vector2i o, const Eigen::Vector3d& lo3, const Eigen::Vector3d& hi3, double reach) const;
  };
  ImageBound image_bound(const Strain& s, const RveState& st) const;

  // Zero modes handled (for reports and tests). The pinned vertex's in-plane components are
  // pinned; its normal component is set from the others' by apply_step, so that the yarns'
  // mean height over the mid-surface (weighted by yarn length) stays at the pattern's.
  int pinned_vertex() const { return pinned_vertex_; }
  double dependent_height(const RveState& st) const;  // the pinned vertex's u_n implied by the others
  double mean_height(const RveState& st) const;       // sum_v w_v u_v,n / sum_v w_v (m)
  const std::vector<int>& slide_pinned() const { return slide_pinned_; }   // vertex per yarn
  const std::vector<int>& twist_pinned() const { return twist_pinned_; }   // vertex per yarn

  // Reduced layout.
  int pos_index(int v) const { return pos_index_[v]; }
  int pos_count(int v) const { return npos_[v]; }
  int theta_index(int v) const { return theta_index_[v]; }
  const Eigen::Matrix3d& basis(int v) const { return basis_[v]; }

 private:
  struct Node;
  Node node(const Strain& s, const RveState& st, int v, Eigen::Vector2i o, bool want_ds) const;
  template <int M>
  void scatter(int nslots, const Node* const* nodes, const int* verts, int nth, const int* thv,
               const Eigen::Matrix<double, M, 1>& gl, const Eigen::Matrix<double, M, M>* Hl,
               Eigen::VectorXd* grad, std::vector<Eigen::Triplet<double>>* hess, Strain* dEds) const;
  static uint64_t pair_key(int a, int b, Eigen::Vector2i o);
  void eliminate_height(Eigen::VectorXd* grad, std::vector<Eigen::Triplet<double>>* hess, size_t hess_start,
                        HeightTerm* height) const;
  double evaluate_all(const Strain& s, const RveState& st, Eigen::VectorXd* grad,
                      std::vector<Eigen::Triplet<double>>* hess, EnergyParts* parts, Strain* dEds,
                      HeightTerm* height) const;
  // evaluate()'s steps (rve.cpp): the points and contact pairs of one evaluation, then each
  // thread's sums over stretch, joint and contact elements.
  struct Assembly;
  struct Sums;
  void prepare(const Strain& s, const RveState& st, Assembly& A) const;
  void stretch_sums(const Assembly& A, Sums& L, int chunk, int chunks) const;
  void joint_sums(const Assembly& A, Sums& L, int chunk, int chunks) const;
  void contact_sums(const Assembly& A, Sums& L, int chunk, int chunks) const;

  Pattern p_;
  Material m_;
  RveOptions opt_;
  Eigen::Matrix2d F0_;
  Topology topo_;
  double EA_, EI_, GJ_;
  ContactParams contact_;
  BarrierParams barrier_;
  int ndof_ = 0;
  std::vector<int> pos_index_, npos_, theta_index_;
  std::vector<Eigen::Matrix3d> basis_;
  Eigen::VectorXd scale_;
  std::vector<double> height_weight_;  // per vertex: half its two edges' rest lengths
  Eigen::VectorXd height_coef_;        // the pinned vertex's u_n = height_coef_ . y
  int pinned_vertex_ = -1;
  std::vector<int> slide_pinned_, twist_pinned_;
  std::unordered_set<uint64_t> excluded_;
};

}  // namespace yarnhom::yarn
