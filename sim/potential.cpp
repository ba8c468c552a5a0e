#include "sim/potential.hpp"

#include <cmath>
#include <limits>

#include "core/scope_profile.hpp"
#include "numerics/barrier.hpp"
#include "sim/garment.hpp"

namespace yarnhom::sim {

Eigen::MatrixX3d vertex_normals(const Mesh& m, const Eigen::VectorXd& x) {
  Eigen::MatrixX3d n = Eigen::MatrixX3d::Zero(m.num_vertices(), 3);
  for (int t = 0; t < m.num_triangles(); ++t) {
    const Eigen::Vector3d a = x.segment<3>(3 * m.tris(t, 0)), b = x.segment<3>(3 * m.tris(t, 1)),
                          c = x.segment<3>(3 * m.tris(t, 2));
    const Eigen::RowVector3d N = (b - a).cross(c - a).transpose();
    for (int i = 0; i < 3; ++i) n.row(m.tris(t, i)) += N;
  }
  for (int v = 0; v < n.rows(); ++v) {
    const double l = n.row(v).norm();
    if (l > 0) n.row(v) /= l;
  }
  return n;
}

namespace {

// Per-vertex terms (everything but the shell and the Rayleigh beta term), value and optional
// gradient / Hessian block.
double vertex_terms(const Problem& P, const StepState& S, const Eigen::VectorXd& x, int v, Eigen::Vector3d* g,
                    Eigen::Matrix3d* H) {
  const Eigen::Vector3d xv = x.segment<3>(3 * v);
  const double m = P.mass[v], A = P.vertex_area[v];
  const Eigen::Vector3d gravity = S.gravity_scale * P.gravity;
  double E = -m * gravity.dot(xv);
  if (g) *g = -m * gravity;
  if (H) H->setZero();
  if (S.dynamic) {
    const double h = S.h;
    const Eigen::Vector3d dx = xv - S.x_tilde.segment<3>(3 * v);
    E += 0.5 * m * dx.squaredNorm() / (h * h);
    if (g) *g += m * dx / (h * h);
    if (H) H->diagonal().array() += m / (h * h);
    const Eigen::Vector3d dv = xv - S.x_prev.segment<3>(3 * v);
    if (P.rayleigh_alpha > 0) {
      const double c = P.rayleigh_alpha * m / h;
      E += 0.5 * c * dv.squaredNorm();
      if (g) *g += c * dv;
      if (H) H->diagonal().array() += c;
    }
    if (P.air_drag > 0) {
      const Eigen::Vector3d n = S.normals.row(v).transpose();
      const double c = P.air_drag * A / h, dn = n.dot(dv);
      E += 0.5 * c * dn * dn;
      if (g) *g += c * dn * n;
      if (H) *H += c * n * n.transpose();
    }
  }
  for (const Collider& c : P.colliders) {
    Eigen::Vector3d dg;
    Eigen::Matrix3d dH;
    const double d = collider_distance(c, xv, g ? &dg : nullptr, H ? &dH : nullptr);
    if (d >= P.dhat) continue;
    const numerics::BarrierValue b = numerics::distance_barrier(d, P.dhat);
    if (!std::isfinite(b.b)) return std::numeric_limits<double>::infinity();
    const double k = P.kappa * A;
    E += k * b.b;
    if (g) *g += k * b.db * dg;
    // b'' >= 0 inside the barrier's range; b' <= 0, so the curvature term of a sphere's
    // distance is negative semi-definite: dropped (its projection).
    if (H) {
      *H += k * b.d2b * dg * dg.transpose();
      if (b.db > 0) *H += k * b.db * dH;
    }
  }
  return E;
}

// E plus the per-vertex terms of every vertex, added in vertex order; with grad, their gradients
// added to it, with values, their Hessian blocks to the free vertices' diagonal blocks. Each
// vertex on its own on the OpenMP threads (it writes only its own entries), the sum after, in
// order: the same on any thread count.
double add_vertex_terms(double E, const Problem& P, const DofMap& D, const StepState& S, const Eigen::VectorXd& x,
                        Eigen::VectorXd* grad, const HessianPattern* pat, double* values) {
  const int n = P.mesh.num_vertices();
  std::vector<double> e(size_t(n), 0.0);
#pragma omp parallel for schedule(static) if (n >= 4096)
  for (int v = 0; v < n; ++v) {
    Eigen::Vector3d g;
    Eigen::Matrix3d H;
    const int f = D.free_index[size_t(v)];
    const bool hess = values && f >= 0;
    e[size_t(v)] = vertex_terms(P, S, x, v, grad ? &g : nullptr, hess ? &H : nullptr);
    if (grad) grad->segment<3>(3 * v) += g;
    if (hess) add_vertex_hessian(*pat, f, H, values);
  }
  for (double ev : e) E += ev;
  return E;
}

}  // namespace

namespace {

// (beta/(2h)) dx^T K_n dx over the free unknowns, with its gradient (scattered to grad) and
// its Hessian (beta/h) K_n added to values (same pattern).
double rayleigh_beta_term(const Problem& P, const DofMap& D, const StepState& S, const Eigen::VectorXd& x,
                          Eigen::VectorXd* grad, double* values) {
  if (!S.dynamic || !(P.rayleigh_beta > 0) || S.K_prev.rows() == 0) return 0.0;
  const double c = P.rayleigh_beta / S.h;
  const Eigen::VectorXd dx = gather_free(D, x) - gather_free(D, S.x_prev);
  const Eigen::VectorXd Kdx = S.K_prev.selfadjointView<Eigen::Lower>() * dx;
  if (grad)
    for (int i = 0; i < D.num_free(); ++i) grad->segment<3>(3 * D.free_vertices[i]) += c * Kdx.segment<3>(3 * i);
  if (values)
    for (Eigen::Index k = 0; k < S.K_prev.nonZeros(); ++k) values[k] += c * S.K_prev.valuePtr()[k];
  return 0.5 * c * dx.dot(Kdx);
}

// potential_value, with (pairs) or without the contact pairs' terms.
double potential_value_terms(const Problem& P, const DofMap& D, const StepState& S, const Eigen::VectorXd& x,
                             double* shell, const double* known_shell, bool pairs) {
  double E;
  {
    prof::Scope ps("energy: elements");
    E = known_shell ? *known_shell
                    : shell_energy(P.mesh, P.rest, P.material, x, S.theta_ref.empty() ? nullptr : S.theta_ref.data(),
                                   &P.material_value);
  }
  if (shell) *shell = E;
  {
    prof::Scope ps("energy: vertex terms");
    E = add_vertex_terms(E, P, D, S, x, nullptr, nullptr, nullptr);
    for (const FrictionContact& c : S.friction) E += friction_energy(c, x.segment<3>(3 * c.vertex), S.friction_eps);
  }
  if (pairs && has_contact(P)) {
    prof::Scope ps("energy: contact");
    const Eigen::VectorXd y = solve_obstacles(P, S);
    E += contact_energy(P, D.free_index, x, y, nullptr, nullptr, S.contact_cache.get());
    if (!S.pair_friction.empty()) E += pair_friction_energy(S.pair_friction, S.friction_eps, D.free_index, x, y);
  }
  if (!P.stitches.empty()) {
    prof::Scope ps("energy: seams");
    E += seam_energy(P, D.free_index, x, S.time);
  }
  return E + rayleigh_beta_term(P, D, S, x, nullptr, nullptr);
}

}  // namespace

double potential_value(const Problem& P, const DofMap& D, const StepState& S, const Eigen::VectorXd& x,
                       double* shell, const double* known_shell) {
  return potential_value_terms(P, D, S, x, shell, known_shell, true);
}

double potential_value_without_pairs(const Problem& P, const DofMap& D, const StepState& S, const Eigen::VectorXd& x,
                                     double* shell, const double* known_shell) {
  return potential_value_terms(P, D, S, x, shell, known_shell, false);
}

double potential_derivatives(const Problem& P, const DofMap& D, const HessianPattern& pat, const StepState& S,
                             const Eigen::VectorXd& x, Eigen::VectorXd& grad, double* values, ShellTimings* timings,
                             double* shell, std::vector<Eigen::Triplet<double>>* contact, const Eigen::VectorXd* move,
                             Eigen::VectorXd* coupling) {
  grad.setZero(x.size());
  double E;
  {
    prof::Scope ps("derivatives: elements");
    E = shell_energy_derivatives(P.mesh, P.rest, P.material, x, grad, values ? &pat : nullptr, values, timings, P.hessian,
                                 S.theta_ref.empty() ? nullptr : S.theta_ref.data(), P.eigen_filter, move, coupling);
  }
  if (shell) *shell = E;
  prof::Scope ps_rest("derivatives: all but the elements");
  E = add_vertex_terms(E, P, D, S, x, &grad, &pat, values);
  for (const FrictionContact& c : S.friction) {
    Eigen::Vector3d g;
    Eigen::Matrix3d H;
    const int f = D.free_index[c.vertex];
    E += friction_energy(c, x.segment<3>(3 * c.vertex), S.friction_eps, &g, values && f >= 0 ? &H : nullptr);
    grad.segment<3>(3 * c.vertex) += g;
    if (values && f >= 0) add_vertex_hessian(pat, f, H, values);
  }
  if (has_contact(P)) {
    prof::Scope ps("derivatives: contact");
    const Eigen::VectorXd y = solve_obstacles(P, S);
    E += contact_energy(P, D.free_index, x, y, &grad, contact, S.contact_cache.get());
    if (!S.pair_friction.empty())
      E += pair_friction_energy(S.pair_friction, S.friction_eps, D.free_index, x, y, &grad, contact,
                                S.pair_friction_majorize);
  }
  if (!P.stitches.empty()) {
    prof::Scope ps("derivatives: seams");
    E += seam_energy(P, D.free_index, x, S.time, &grad, contact);
  }
  return E + rayleigh_beta_term(P, D, S, x, &grad, values);
}

double external_potential(const Problem& P, const Eigen::VectorXd& x) {
  StepState st;
  st.dynamic = false;
  double E = 0;
  for (int v = 0; v < P.mesh.num_vertices(); ++v) E += vertex_terms(P, st, x, v, nullptr, nullptr);
  return E;
}

Eigen::VectorXd potential_energy_gradient(const Problem& P, const Eigen::VectorXd& x) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  shell_energy_derivatives(P.mesh, P.rest, P.material, x, g, nullptr, nullptr);
  StepState st;
  st.dynamic = false;
  for (int v = 0; v < P.mesh.num_vertices(); ++v) {
    Eigen::Vector3d gv;
    vertex_terms(P, st, x, v, &gv, nullptr);
    g.segment<3>(3 * v) += gv;
  }
  return g;
}

Eigen::VectorXd solve_obstacles(const Problem& P, const StepState& S) {
  if (S.obstacle_y.size() == 3 * P.obstacles.num_points) return S.obstacle_y;
  return obstacle_positions(P.obstacles, 0.0);
}

double max_feasible_step(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& p, const StepState* S) {
  prof::Scope ps("CCD (max_feasible_step)");
  double tc = 1.0;
  if (S && has_contact(P)) {
    const Eigen::VectorXd y = solve_obstacles(P, *S);
    tc = contact_step_bound(P, x, p, y, Eigen::VectorXd::Zero(y.size()), nullptr, S->contact_cache.get());
  }
  double t = 1.0;
  for (const Collider& c : P.colliders)
    for (int v = 0; v < P.mesh.num_vertices(); ++v) {
      const Eigen::Vector3d pv = p.segment<3>(3 * v);
      if (pv.squaredNorm() == 0) continue;
      t = std::min(t, collider_time_of_impact(c, x.segment<3>(3 * v), pv));
    }
  return std::min(t < 1.0 ? 0.9 * t : 1.0, tc);
}

Eigen::VectorXd feasible_prediction(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& dx) {
  Eigen::VectorXd xn = x + dx;
  for (int v = 0; v < P.mesh.num_vertices(); ++v) {
    const Eigen::Vector3d pv = dx.segment<3>(3 * v);
    if (pv.squaredNorm() == 0) continue;
    for (const Collider& c : P.colliders)
      if (collider_time_of_impact(c, x.segment<3>(3 * v), pv) < 1.0) {
        xn.segment<3>(3 * v) = x.segment<3>(3 * v);
        break;
      }
  }
  return xn;
}

Eigen::SparseMatrix<double> elastic_hessian(const Problem& P, const HessianPattern& pat, const Eigen::VectorXd& x) {
  Eigen::SparseMatrix<double> K;
  copy_pattern(pat.matrix, K);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  shell_energy_derivatives(P.mesh, P.rest, P.material, x, g, &pat, K.valuePtr(), nullptr, P.hessian, nullptr,
                           P.eigen_filter);
  return K;
}

}  // namespace yarnhom::sim
