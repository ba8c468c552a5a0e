#pragma once
// The mechanics of a yarn strip (docs/strip.md): the same energy as the RVE (discrete elastic
// rods + yarn-yarn contact, docs/rve.md section 3) on one non-periodic yarn, with some
// vertices held by clamps. Unknowns: the position of every free vertex and the twist angle of
// every edge that is not held at both ends, grouped per vertex (its position, then the angle
// of its outgoing edge). Exact gradient and Hessian (lower triangle, assembled in place:
// numerics/block_hessian.hpp) in those unknowns, the gradient with respect to every vertex position
// (for the clamp reactions), a step filter and a certificate.
//
// Boundary yarn (Strip::connector_edge / connector_joint) has its stretching, bending and
// twisting moduli scaled by Strip::connector_scale; contact is the same for every segment.
//
// Reference frames (as in the RVE, FrameState in rve.hpp) are fixed during a solve: the
// energy is one smooth function of the unknowns, its derivatives are exact and the envelope
// theorem holds. Between load steps the stretch test re-bases them on the current tangents
// (rebase_frames), which leaves the energy unchanged at that state; with no periodic images,
// nothing is lost by it (contrast docs/rve.md section 3), and it keeps every transport far
// from the antiparallel singularity however far the yarns turn over 70 % of stretch.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <utility>
#include <vector>

#include "numerics/block_hessian.hpp"
#include "yarn/rod/contact_certificate.hpp"
#include "yarn/rod/energy_parts.hpp"
#include "yarn/rod/material.hpp"
#include "yarn/rod/rod.hpp"
#include "yarn/strip/strip.hpp"
#include "yarn/strip/strip_contact.hpp"

namespace yarnhom::yarn {

using numerics::BlockHessian;

struct StripState {
  std::vector<Eigen::Vector3d> x;  // per vertex (m); clamped ones where their clamp holds them
  std::vector<double> theta;       // per edge (rad)
  std::vector<EdgeFrame> frames;   // per edge: reference frame, fixed during a solve
  std::vector<double> twist;       // per vertex: reference twist of the frames (its branch)
  // What the collision checks of every move since the generated strip found (each Newton
  // step and each predictor is a straight move of the vertices): valid when no pair of
  // segments that may touch ever came within d_min (yarn/rod/contact_certificate.hpp).
  ContactCertificate certificate;
};

struct StripOptions {
  StripContactOptions contact;   // as RveOptions: kernel quadrature, barrier d_min, d_hat, scale
  double exclusion_arc = M_PI;   // in yarn radii, as in RveOptions
  // In yarn radii: contact pairs this far beyond reach enter the Hessian's pattern (with zero
  // values) so that it changes less often. 0 for strips: the pattern changes at almost every
  // iteration anyway (loops slide), its analysis is cheap, and the extra entries fill the
  // factor in: on the paper's stockinette strip 0.5 gave 2e9 flops per factorization, 0 gives
  // 5e8, the 100 % step 34 s -> 15 s with the same iterates (docs/benchmarks.md).
  double hessian_margin = 0.0;
};

class StripProblem {
 public:
  // clamp: per vertex, 0 free, -1 or +1 held by the clamp at the low or high end of the long
  // axis. A clamped vertex is not an unknown; an edge with both ends clamped keeps its twist.
  StripProblem(Strip strip, Material material, std::vector<signed char> clamp, StripOptions options = {});

  const Strip& strip() const { return s_; }
  const Material& material() const { return m_; }
  const std::vector<signed char>& clamp() const { return clamp_; }
  int num_dofs() const { return ndof_; }
  double radius() const { return s_.radius; }
  double stretch_stiffness() const { return EA_; }
  // Per reduced dof: 1 for positions, 1/r for twist angles (moments -> forces), for residuals.
  const Eigen::VectorXd& force_scale() const { return scale_; }
  int pos_index(int v) const { return pos_index_[v]; }      // -1 when clamped
  int theta_index(int e) const { return theta_index_[e]; }  // -1 when held

  // The strip's geometry and frames.
  StripState initial_state() const;

  // An empty Hessian of the right layout for evaluate().
  BlockHessian make_hessian() const;

  // Which element Hessians evaluate() replaces by their projection onto the positive
  // semi-definite cone (negative eigenvalues set to 0): none (the exact Hessian); those of
  // boundary-yarn joints only (their twist angles are nearly free, 1/200 of the twisting
  // modulus, and their bend-twist coupling makes them non-convex wherever the soft yarn is bent
  // away from its rest curvature: measured, the exact Hessian's only negative modes on a
  // stretched stockinette strip were twist angles of bind-off rows); or all (stretch, joints,
  // contact pairs: a convex model far from equilibrium, where soft boundary yarn pressed by
  // contact makes the exact Hessian strongly indefinite).
  enum class Projection { kNone, kBoundaryJoints, kAll };

  // Energy; with grad: the gradient in the unknowns; with hess: the Hessian (its pattern set
  // to the elements present now, with the contact pairs up to hessian_margin beyond reach);
  // with vertex_grad: dE/dx of every vertex, clamped or not.
  // With projected (hess given too): the Hessian with every element's Hessian projected
  // (Projection::kAll) in the same pass, for a solver that uses both.
  double evaluate(const StripState& st, Eigen::VectorXd* grad = nullptr, BlockHessian* hess = nullptr,
                  EnergyParts* parts = nullptr, std::vector<Eigen::Vector3d>* vertex_grad = nullptr,
                  Projection project = Projection::kNone, BlockHessian* projected = nullptr) const;

  // st += alpha dy in the unknowns.
  void apply_step(const Eigen::VectorXd& dy, double alpha, StripState& st) const;
  // Collision filter: the fraction of the straight move from st to st + dy (unknowns) along
  // which every pair of segments that may touch stays above d_min (CCD; 1: all of it).
  double step_bound(const StripState& st, const Eigen::VectorXd& dy) const;
  // The same for a move of every vertex from `from` to `to` (a predictor, clamps included).
  double safe_fraction(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) const;
  // The closest distance between any two segments that may touch, divided by 2r (1 = surfaces
  // touching, 0 = centrelines crossing); +inf if no pair is within 2r.
  double min_distance(const StripState& st) const;
  const StripContact& contact() const { return contact_; }
  // Re-bases the reference frames on the current tangents (the energy is unchanged).
  void rebase_frames(StripState& st) const;
  // Keeps the frames usable along a long solve without changing the energy at st: every
  // joint's reference twist takes its current value as its branch (the branch nearest the
  // stored value is used, so a joint twisting by more than pi during one solve would
  // otherwise jump by 2 pi: an energy wall that stalls the line search), and an edge whose
  // tangent turned by more than `max_turn` (rad) from its frame's gets that frame re-based
  // (parallel transport is singular at a half turn).
  void track_frames(StripState& st, double max_turn = M_PI / 3) const;

  // Segment pairs that may interact: rest arc gap >= exclusion_arc radii and closest distance
  // below 2r + margin; candidates from a hash grid (numerics/hash_grid.hpp); sorted.
  std::vector<std::pair<int, int>> contact_pairs(const StripState& st, double margin) const;
  bool excluded(int a, int b) const;

 private:
  // evaluate()'s steps (strip_problem.cpp): the Hessian's pattern, then each thread's sums over
  // stretch, joint and contact elements.
  struct Assembly;
  struct Sums;
  void set_hessian_pattern(const std::vector<std::pair<int, int>>& pairs, BlockHessian* hess,
                           BlockHessian* projected) const;
  void stretch_sums(const StripState& st, const Assembly& A, Sums& L) const;
  void joint_sums(const StripState& st, const Assembly& A, Sums& L) const;
  void contact_sums(const StripState& st, const Assembly& A, Sums& L) const;

  Strip s_;
  Material m_;
  std::vector<signed char> clamp_;
  StripOptions opt_;
  StripContact contact_;
  double EA_, EI_, GJ_;
  int ndof_ = 0;
  std::vector<int> pos_index_, theta_index_, node_first_, node_count_;
  Eigen::VectorXd scale_;
  std::vector<double> arc_;  // arc_[e]: rest arc length from vertex 0 to the start of edge e
};

}  // namespace yarnhom::yarn
