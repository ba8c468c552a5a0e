#pragma once
// The function each solve minimizes (spec section 10; IPC's incremental potential). In a
// dynamic step of size h, with x_n the current positions and x~ = x_n + h v_n,
//
//   Phi(x) = 1/(2h^2) |x - x~|_M^2                        inertia (lumped M)
//          + E_shell(x)                                   sim/shell_energy.hpp
//          - sum_v m_v g . x_v                            gravity
//          + kappa sum_v sum_c A_v b(d_c(x_v))            colliders (numerics/barrier.hpp)
//          + 1/(2h) (x - x_n)^T (alpha M + beta K_n) (x - x_n)     Rayleigh damping
//          + c_air/(2h) sum_v A_v ((x_v - x_v^n) . n_v)^2        air drag on the normal velocity
//          + sum_k mu lambda_k f0(|T_k^T (x_k - x_k^n)|)            lagged friction (sim/friction.hpp)
//          + sum_pairs kappa_J b(z(D_pair(x, y)))                   surface contact (sim/contact.hpp):
//            the cloth with itself and with the obstacles, at their positions y for this solve
//          + sum_pairs mu lambda f0(|u_pair|)                       ... and its lagged friction
//
// whose stationarity is implicit Euler with those forces: M (x - x~)/h^2 = f(x), damping
// forces -(alpha M + beta K_n) v and -c_air A (v.n) n with v = (x - x_n)/h (K_n and n_v frozen at
// x_n, so the damping terms are exact quadratics). In a static solve only the elastic, gravity,
// collider and friction terms remain: equilibrium is the minimum of the potential energy (plus
// the friction of the displacement from the previous load step).
#include <Eigen/Sparse>
#include <memory>

#include "sim/contact.hpp"
#include "sim/dof_map.hpp"
#include "sim/friction.hpp"
#include "sim/hessian_pattern.hpp"
#include "sim/problem.hpp"
#include "sim/shell_energy.hpp"

namespace yarnhom::sim {

struct StepState {
  bool dynamic = true;
  double h = 0;
  Eigen::VectorXd x_tilde;  // 3n, x_n + h v_n
  Eigen::VectorXd x_prev;   // 3n, x_n
  Eigen::MatrixX3d normals; // [n] unit vertex normals at x_n (air drag)
  Eigen::SparseMatrix<double> K_prev;  // lower triangle over the free unknowns (the pattern's),
                                       // projected elastic Hessian at x_n (beta damping)
  std::vector<FrictionContact> friction;  // lagged contacts (sim/friction.hpp); empty: frictionless
  double friction_eps = 0;                // m, eps_v h (statics: eps_v x 1 s)
  double time = 0;                   // s, the step's end (seams, gravity delay)
  double gravity_scale = 1;          // 0 before the problem's gravity delay
  Eigen::VectorXd obstacle_y;        // 3K obstacle positions during this solve (sim/obstacles.hpp)
  Eigen::VectorXd obstacle_y_start;  // ... at the step's start (friction's slip)
  std::vector<PairFriction> pair_friction;  // lagged friction of contact pairs (sim/contact.hpp)
  bool pair_friction_majorize = false;      // ... with the majorizing Hessian (pair_friction_energy)
  // The step's contact broad phase (sim/contact_broad_phase.hpp), shared by its evaluations and
  // CCDs; null: a fresh broad phase per call (the simulator sets it with self-collision on).
  std::shared_ptr<ContactCache> contact_cache;
  std::vector<double> theta_ref;  // 3 per triangle: the dihedral angles' branches (sim/hinge_angles.hpp); empty: (-pi, pi]
};

// Unit area-weighted vertex normals.
Eigen::MatrixX3d vertex_normals(const Mesh& mesh, const Eigen::VectorXd& x);

// +inf when a vertex is on or inside a collider. shell (optional): E_shell(x) alone.
// known_shell (optional): E_shell(x) already known (on S's branches): used instead of a pass.
double potential_value(const Problem& P, const DofMap& D, const StepState& S, const Eigen::VectorXd& x,
                       double* shell = nullptr, const double* known_shell = nullptr);
// The same without the contact pairs' terms (their barrier and friction, both >= 0): a lower
// bound of potential_value at x, without the pairs' broad phase.
double potential_value_without_pairs(const Problem& P, const DofMap& D, const StepState& S, const Eigen::VectorXd& x,
                                     double* shell = nullptr, const double* known_shell = nullptr);

// Value; gradient (3n, every vertex) written to grad; Hessian over the free vertices added to
// values (the pattern's value array) when given. shell (optional): E_shell(x) alone.
// contact (optional): the contact pairs' Hessian (barrier and friction, lower triangle over the
// free unknowns) as triplets, which may couple vertices outside the pattern; without it the
// contact Hessian is left out (the gradient always has it).
// move, coupling (optional, with values): the shell's model Hessian applied to move, added to
// coupling (sim/shell_energy.hpp); the per-vertex and contact terms couple no free vertex to a
// prescribed one in the matrix and add nothing.
double potential_derivatives(const Problem& P, const DofMap& D, const HessianPattern& pat, const StepState& S,
                             const Eigen::VectorXd& x, Eigen::VectorXd& grad, double* values,
                             ShellTimings* timings = nullptr, double* shell = nullptr,
                             std::vector<Eigen::Triplet<double>>* contact = nullptr,
                             const Eigen::VectorXd* move = nullptr, Eigen::VectorXd* coupling = nullptr);

// The potential energy's per-vertex part, gravity and colliders (what a static state's
// potential_value adds to E_shell): O(vertices), so that a step that knows E_shell at its end
// (NewtonStats::shell_energy) records its potential energy without another element pass.
double external_potential(const Problem& P, const Eigen::VectorXd& x);

// Gradient of the potential energy E_shell + gravity + colliders at every vertex: at a
// prescribed vertex, the force its clamp or handle exerts on the cloth (at equilibrium).
Eigen::VectorXd potential_energy_gradient(const Problem& P, const Eigen::VectorXd& x);

// Largest step fraction in (0, 1] along p (3n) that keeps every vertex outside the colliders,
// scaled by 0.9 when limited (IPC's filtered line search).
// With S (optional), contact pairs bound it too (sim/contact.hpp: contact_step_bound, obstacles
// held at S.obstacle_y).
double max_feasible_step(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& p,
                         const StepState* S = nullptr);

// The obstacle positions of a solve: S's, else the obstacles at t = 0.
Eigen::VectorXd solve_obstacles(const Problem& P, const StepState& S);

// A time step's initial guess x + dx, vertex by vertex: a vertex whose own move would reach a
// collider stays where it is; every other vertex takes its whole move. (Shortening the whole
// move by the first impact, as the line search does, froze a draped sheet: one vertex of a
// curling material pressed towards the sphere shortened every vertex's inertial prediction to
// 0.9 of its distance, step after step; its distance fell tenfold per step, below the Newton
// tolerance, which then accepted the guess, until rounding put it inside and the energy was
// infinite at step 61 of the demo model's drape. From its old place the barrier acts on it.)
Eigen::VectorXd feasible_prediction(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& dx);

// Projected elastic Hessian alone (for Rayleigh damping's K_n).
Eigen::SparseMatrix<double> elastic_hessian(const Problem& P, const HessianPattern& pat, const Eigen::VectorXd& x);

}  // namespace yarnhom::sim
