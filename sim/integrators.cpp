#include "sim/integrators.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "core/scope_profile.hpp"
#include "sim/hinge_angles.hpp"

namespace yarnhom::sim {

namespace {
using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// The branches for a step that starts at x: the carried angles brought to x, or (-pi, pi].
std::vector<double> step_branches(const Mesh& m, const Eigen::VectorXd& x, const std::vector<double>* hinges) {
  return hinge_angles(m, x, hinges && !hinges->empty() ? hinges : nullptr);
}

// A re-solve's work added to the step's: counts and times add up, the outcome is the last one's.
void accumulate(NewtonStats& into, const NewtonStats& more) {
  into.iterations += more.iterations;
  into.shifted += more.shifted;
  into.backtracks += more.backtracks;
  into.extensions += more.extensions;
  into.factorizations += more.factorizations;
  into.cg_iterations += more.cg_iterations;
  into.reused += more.reused;
  into.evaluations += more.evaluations;
  into.t_assemble += more.t_assemble;
  into.t_solve += more.t_solve;
  into.t_line_search += more.t_line_search;
  into.shell += more.shell;
  into.converged = more.converged;
  into.energy = more.energy;
  into.step_norm = more.step_norm;
  into.shell_energy = more.shell_energy;
  into.prescribed_reached = more.prescribed_reached;
}

// Minimizes with the friction lagged at x_start, then (IPC's lag update) P.friction_updates
// times more with the normal forces and tangent bases taken at the solution, u still measured
// from x_start.
NewtonStats minimize_with_friction(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                                   StepState& S, const Eigen::VectorXd& x_start, double eps, Eigen::VectorXd& x,
                                   const NewtonSettings& opt, bool profile, const Eigen::VectorXd* target = nullptr) {
  const bool friction = has_friction(P);
  if (friction) {
    S.friction = friction_contacts(P, D.free_index, x_start, x_start);
    S.friction_eps = eps;
  }
  if (has_contact(P)) {
    const Eigen::VectorXd y = solve_obstacles(P, S);
    const Eigen::VectorXd y0 = S.obstacle_y_start.size() == y.size() ? S.obstacle_y_start : y;
    S.pair_friction = pair_friction_contacts(P, x_start, y0, x_start, y0, S.contact_cache.get());
    S.friction_eps = eps;
  }
  NewtonStats st = newton_minimize(P, D, pat, solver, S, x, opt, profile, target);
  // Lag updates are more solves: the one-solve step (max_iterations 1) keeps the step-start lag.
  const int updates = opt.max_iterations == 1 ? 0 : P.friction_updates;
  for (int k = 0; friction && k < updates && x.allFinite(); ++k) {
    S.friction = friction_contacts(P, D.free_index, x, x_start);
    accumulate(st, newton_minimize(P, D, pat, solver, S, x, opt, profile));
  }
  return st;
}
}  // namespace

void apply_targets(const DofMap& D, const Eigen::VectorXd& target, Eigen::VectorXd& x) {
  for (size_t v = 0; v < D.free_index.size(); ++v)
    if (D.free_index[v] < 0) x.segment<3>(3 * v) = target.segment<3>(3 * v);
}

StepStats implicit_euler_step(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                              Eigen::VectorXd& x, Eigen::VectorXd& v, const Eigen::VectorXd& target, double h,
                              const NewtonSettings& opt, bool profile, std::vector<double>* hinges,
                              double potential_at_x, ObstacleMotion* obstacles) {
  StepState S;
  S.dynamic = true;
  std::optional<prof::Scope> ps_start;
  ps_start.emplace("step start (before the first solve)");
  S.theta_ref = step_branches(P.mesh, x, hinges);
  S.h = h;
  S.x_prev = x;
  S.x_tilde = x + h * v;
  if (P.air_drag > 0) S.normals = vertex_normals(P.mesh, x);
  if (P.rayleigh_beta > 0) S.K_prev = elastic_hessian(P, pat, x);
  const bool contact = has_contact(P);
  // One broad phase serves the step's evaluations where their positions allow
  // (sim/contact_broad_phase.hpp); without self-collision every call keeps its own.
  if (P.self_collision) {
    std::shared_ptr<ContactCache>& kept = obstacles ? obstacles->contact_cache : S.contact_cache;
    if (!kept) kept = std::make_shared<ContactCache>();
    S.contact_cache = kept;
  }
  ContactCache* cache = S.contact_cache.get();
  if (obstacles) {
    S.time = obstacles->time;
    if (P.gravity_delay > 0 && S.time < P.gravity_delay) S.gravity_scale = 0;
  }
  Eigen::VectorXd y0, y1;
  if (contact) {
    y0 = obstacles ? obstacles->y : obstacle_positions(P.obstacles, 0.0);
    y1 = obstacles ? obstacles->target : y0;
    S.obstacle_y_start = y0;
    S.obstacle_y = y1;
  }
  // The one-solve step while an obstacle moves (sim/integrators.hpp): the pairs' friction with
  // its majorizing Hessian, and up to three more iterations where a solve's step was cut short.
  // The same extra iterations while gravity pulls a garment whose seams are still closing (the
  // step ends before the sewing time): the half-sewn shirt falls onto the body, CCD cuts the one
  // solve's step to 5-32 %, and the cloth kept the rest of the prediction's stretch.
  NewtonSettings sopt = opt;
  if (opt.max_iterations == 1 && contact && y1 != y0) {
    sopt.extra_when_cut = 3;
    S.pair_friction_majorize = true;
  }
  const bool sewing_under_gravity =
      !P.stitches.empty() && S.time < P.sew_time && S.gravity_scale > 0 && P.gravity.squaredNorm() > 0;
  if (opt.max_iterations == 1 && contact && sewing_under_gravity) sopt.extra_when_cut = std::max(sopt.extra_when_cut, 3);
  // Initial guess: the inertial prediction, vertex by vertex outside the colliders
  // (feasible_prediction); then the prescribed vertices at their targets. With the prescribed
  // vertices moved within the solve (opt.prescribed_in_solve: the one-solve step), neither start
  // moves them ahead of the cloth: they stay at x_n there, or take their own h v_n in the
  // prediction, and newton_minimize moves them to their targets with the cloth's response.
  const bool in_solve = opt.prescribed_in_solve;
  const Eigen::VectorXd* solve_target = in_solve ? &target : nullptr;
  Eigen::VectorXd dx = h * v;
  if (!in_solve)
    for (size_t i = 0; i < D.free_index.size(); ++i)
      if (D.free_index[i] < 0) dx.segment<3>(3 * i).setZero();
  Eigen::VectorXd xn = feasible_prediction(P, x, dx);
  if (!in_solve) apply_targets(D, target, xn);
  // Newton starts from whichever of the prediction and x_n has the lower incremental potential:
  // the prediction may land where the energy is huge or infinite (a triangle carried past the
  // collapse guard's limit, material/collapse_guard.hpp), and a step that only decreases Phi from
  // there bounds nothing. From x_n, Phi(x_{n+1}) <= Phi(x_n) = T_n + E_n (kinetic plus potential
  // energy; the damping terms vanish there), so no step, converged or not, creates energy
  // beyond E_{n+1} <= T_n + E_n. With contact, both are first made safe to reach from x_n.
  // The safe fraction of the move x_n -> xn (y0 -> y1) as make_move_safe leaves it: the first
  // stage's bound below, not computed again.
  double t_first = -1;
  {
    Eigen::VectorXd xs = x;
    if (!in_solve) apply_targets(D, target, xs);
    double t_s = 1, t_n = 1;
    if (contact) {
      prof::Scope ps("step start: make the moves safe");
      t_s = make_move_safe(P, D.free_index, x, xs, y0, y1, 6, cache);
    }
    double phi_start;
    if (std::isfinite(potential_at_x) && xs == x && !contact) {
      // Phi(x_n) = the inertia term, which is the kinetic energy there, plus the potential
      // energy; the damping terms vanish at x_n and friction is not yet lagged.
      double kinetic = 0;
      for (int i = 0; i < P.mesh.num_vertices(); ++i) kinetic += 0.5 * P.mass[i] * v.segment<3>(3 * i).squaredNorm();
      phi_start = kinetic + potential_at_x;
    } else if (std::isfinite(potential_at_x) && xs == x && P.self_collision) {
      // The same with contact: the recorded potential's shell energy (the record's E_shell plus
      // external_potential) spares the pass over the elements; the contact, seam and inertia
      // terms are evaluated. (Self-collision only: without it, the step stays as it was.)
      const double shell_at_x = potential_at_x - external_potential(P, x);
      phi_start = potential_value(P, D, S, xs, nullptr, &shell_at_x);
    } else {
      phi_start = potential_value(P, D, S, xs);
    }
    // With contact, the obstacles still and no seams, the prediction is made safe (CCD rounds
    // over its whole move) only when its potential without the contact pairs' terms (>= 0) is
    // below phi_start: above it, it is rejected as it is, and the step starts from x_n (which
    // keeps the bound above). Making it safe holds vertices back at x_n, which raised the
    // potential in all but 1 of 179 such steps measured (docs/sim.md, "The step's start"); in
    // a garment (a moving body carries vertices, seams pull panels together) it lowered it in
    // 1 of 10, so there the prediction is always made safe. (A falling sheet's prediction is
    // above x_n's in nearly every step: its velocities carry the last step's curl and
    // rounding, extrapolated.)
    double phi_pred;
    if (contact) {
      double shell_raw = NAN;
      const bool still = y1 == y0 && P.stitches.empty();
      const double phi_raw = still ? potential_value_without_pairs(P, D, S, xn, &shell_raw) : 0.0;
      if (still && !(phi_raw <= phi_start) && std::isfinite(phi_start)) {
        phi_pred = phi_raw;
      } else {
        const Eigen::VectorXd raw = xn;
        {
          prof::Scope ps("step start: make the moves safe");
          t_n = make_move_safe(P, D.free_index, x, xn, y0, y1, 6, cache);
        }
        phi_pred = potential_value(P, D, S, xn, nullptr, still && xn == raw ? &shell_raw : nullptr);
      }
    } else {
      phi_pred = potential_value(P, D, S, xn);
    }
    t_first = t_n;
    if (!(phi_pred <= phi_start) && std::isfinite(phi_start)) {
      xn = xs;
      t_first = t_s;
    }
  }
  ps_start.reset();
  StepStats out;
  // A prescribed move cut short (CCD, or an infinite potential on the way) goes on in another
  // solve from where the last one ended, at most max_stages solves in all.
  const int stages = obstacles ? std::max(1, obstacles->max_stages) : 8;
  if (!contact) {
    for (int stage = 0; stage < stages; ++stage) {
      const NewtonStats ns = minimize_with_friction(P, D, pat, solver, S, x, P.friction_eps_v * h, xn, sopt, profile, solve_target);
      if (stage == 0) out.newton = ns;
      else accumulate(out.newton, ns);
      ++out.contact_stages;
      if (ns.prescribed_reached || !xn.allFinite()) break;
    }
  } else {
    // Stages: move (x_cur -> xn, y_cur -> y1) by what CCD allows, solve, go on from there.
    Eigen::VectorXd xcur = x, ycur = y0;
    for (int stage = 0; stage < stages; ++stage) {
      // make_move_safe returns contact_step_bound(P, xcur, xn - xcur, ycur, y1 - ycur) of the
      // move it leaves (the same call on the same arguments).
      double t = t_first;
      if (stage > 0) {
        if (!in_solve) apply_targets(D, target, xn);
        t = make_move_safe(P, D.free_index, xcur, xn, ycur, y1, 6, cache);
      }
      // ... and by the colliders: a carried vertex must not be moved through a floor.
      for (const Collider& c : P.colliders)
        for (int v = 0; v < P.mesh.num_vertices(); ++v) {
          const Eigen::Vector3d pv = xn.segment<3>(3 * v) - xcur.segment<3>(3 * v);
          if (pv.squaredNorm() > 0) t = std::min(t, collider_time_of_impact(c, xcur.segment<3>(3 * v), pv));
        }
      if (stage > 0 && !(t > 0)) {  // nothing can move further: the obstacle lags
        xn = xcur;                    // (not the target make_move_safe just changed)
        break;
      }
      const bool whole = t >= 1;
      if (!whole) {
        const double f = 0.9 * t;
        xn = xcur + f * (xn - xcur);
        S.obstacle_y = ycur + f * (y1 - ycur);
      } else {
        S.obstacle_y = y1;
      }
      const NewtonStats ns = minimize_with_friction(P, D, pat, solver, S, x, P.friction_eps_v * h, xn, sopt, profile, solve_target);
      if (stage == 0) out.newton = ns;
      else accumulate(out.newton, ns);
      ++out.contact_stages;
      xcur = xn;
      ycur = S.obstacle_y;
      if ((whole && ns.prescribed_reached) || !xn.allFinite()) break;
    }
    if (obstacles) obstacles->y = ycur;
  }
  if (hinges) *hinges = hinge_angles(P.mesh, xn, &S.theta_ref);
  v = (xn - x) / h;
  x = xn;
  out.finite = x.allFinite() && v.allFinite();
  return out;
}

StepStats linearized_step(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                          Eigen::VectorXd& x, Eigen::VectorXd& v, const Eigen::VectorXd& target, double h,
                          const NewtonSettings& opt, bool profile, std::vector<double>* hinges,
                          double potential_at_x, ObstacleMotion* obstacles) {
  NewtonSettings one = opt;
  one.max_iterations = 1;
  one.prescribed_in_solve = true;
  StepStats st = implicit_euler_step(P, D, pat, solver, x, v, target, h, one, profile, hinges, potential_at_x, obstacles);
  st.newton.converged = st.finite;  // one solve by design: nothing to converge
  return st;
}

StepStats baraff_witkin_step(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                             Eigen::VectorXd& x, Eigen::VectorXd& v, const Eigen::VectorXd& target, double h,
                             bool profile, std::vector<double>* hinges) {
  StepStats out;
  auto t0 = Clock::now();
  // Prescribed vertices move first; their velocity over the step is known.
  Eigen::VectorXd xs = x;
  apply_targets(D, target, xs);
  for (size_t i = 0; i < D.free_index.size(); ++i)
    if (D.free_index[i] < 0) v.segment<3>(3 * i) = (xs.segment<3>(3 * i) - x.segment<3>(3 * i)) / h;
  // f = -grad(E_shell + gravity) and K over the free vertices (no collider barrier here).
  Eigen::SparseMatrix<double> K = pat.matrix;
  std::fill(K.valuePtr(), K.valuePtr() + K.nonZeros(), 0.0);
  Eigen::VectorXd grad = Eigen::VectorXd::Zero(x.size());
  const std::vector<double> ref = step_branches(P.mesh, xs, hinges);
  shell_energy_derivatives(P.mesh, P.rest, P.material, xs, grad, &pat, K.valuePtr(),
                           profile ? &out.newton.shell : nullptr, P.hessian, ref.data(), P.eigen_filter);
  const int F = D.num_free();
  Eigen::VectorXd vf(3 * F), rhs(3 * F);
  const Eigen::MatrixX3d normals = P.air_drag > 0 ? vertex_normals(P.mesh, xs) : Eigen::MatrixX3d();
  for (int i = 0; i < F; ++i) {
    const int vtx = D.free_vertices[i];
    vf.segment<3>(3 * i) = v.segment<3>(3 * vtx);
    const double m = P.mass[vtx];
    rhs.segment<3>(3 * i) = h * (-grad.segment<3>(3 * vtx) + m * P.gravity - P.rayleigh_alpha * m * v.segment<3>(3 * vtx));
  }
  // Kv with K symmetric (lower stored); then A = M(1 + h alpha) + h(h + beta) K (+ air).
  const Eigen::VectorXd Kv = K.selfadjointView<Eigen::Lower>() * vf;
  rhs -= h * (h + P.rayleigh_beta) * Kv;
  Eigen::SparseMatrix<double> A = K * (h * (h + P.rayleigh_beta));
  for (int i = 0; i < F; ++i) {
    const int vtx = D.free_vertices[i];
    Eigen::Matrix3d B = Eigen::Matrix3d::Identity() * P.mass[vtx] * (1 + h * P.rayleigh_alpha);
    if (P.air_drag > 0) {
      const Eigen::Vector3d n = normals.row(vtx).transpose();
      const Eigen::Matrix3d C = P.air_drag * P.vertex_area[vtx] * n * n.transpose();
      B += h * C;
      rhs.segment<3>(3 * i) -= h * C * v.segment<3>(3 * vtx);
    }
    add_vertex_hessian(pat, i, B, A.valuePtr());
  }
  auto t1 = Clock::now();
  out.newton.t_assemble = seconds(t0, t1);
  bool ok = solver.factorize(A);
  if (!ok) {
    out.finite = false;
    return out;
  }
  const Eigen::VectorXd dv = solver.solve(rhs);
  out.newton.t_solve = seconds(t1, Clock::now());
  out.newton.iterations = 1;
  out.newton.converged = true;
  for (int i = 0; i < F; ++i) {
    const int vtx = D.free_vertices[i];
    v.segment<3>(3 * vtx) += dv.segment<3>(3 * i);
    xs.segment<3>(3 * vtx) += h * v.segment<3>(3 * vtx);
  }
  // Collider projection.
  for (int i = 0; i < F; ++i) {
    const int vtx = D.free_vertices[i];
    for (const Collider& c : P.colliders) {
      Eigen::Vector3d n;
      const double d = collider_distance(c, xs.segment<3>(3 * vtx), &n);
      if (!(d < P.dhat)) continue;
      xs.segment<3>(3 * vtx) += (P.dhat - d) * n;
      const double vn = v.segment<3>(3 * vtx).dot(n);
      if (vn < 0) v.segment<3>(3 * vtx) -= vn * n;
      ++out.projected_vertices;
    }
  }
  if (hinges) *hinges = hinge_angles(P.mesh, xs, &ref);
  x = xs;
  out.finite = x.allFinite() && v.allFinite();
  return out;
}

StepStats static_solve(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                       Eigen::VectorXd& x, const Eigen::VectorXd& target, const NewtonSettings& opt, bool profile,
                       std::vector<double>* hinges, const Eigen::VectorXd* friction_start) {
  StepState S;
  S.dynamic = false;
  const Eigen::VectorXd x_start = friction_start ? *friction_start : x;
  apply_targets(D, target, x);
  S.theta_ref = step_branches(P.mesh, x, hinges);
  StepStats out;
  // No time step: eps is a displacement per load step, eps_v times one second.
  out.newton = minimize_with_friction(P, D, pat, solver, S, x_start, P.friction_eps_v * 1.0, x, opt, profile);
  if (hinges) *hinges = hinge_angles(P.mesh, x, &S.theta_ref);
  out.finite = x.allFinite();
  return out;
}

}  // namespace yarnhom::sim
