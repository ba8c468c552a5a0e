#pragma once
// Newton's method with line search on the potential of sim/potential.hpp (IPC's solver
// structure): projected element Hessians make the matrix positive semi-definite; the mass
// term (dynamics) or a diagonal shift added only when a factorization fails (statics, where
// free rigid modes or a flat sheet's missing out-of-plane stiffness make it singular) makes it
// definite; the step is limited by continuous collision detection against the colliders and
// then backtracked until it decreases the potential (Armijo).
//
// Converged when the Newton step's largest vertex displacement is below tol_step (m): in a
// dynamic step that is a velocity error below tol_step / h (IPC's criterion; the simulation's
// default is tol_step = 1e-2 l h, l the sheet's rest diagonal, as in IPC).
//
// Factor reuse (NewtonSettings::reuse_cg > 0, `sim --factor-reuse`; off by default): an
// iteration after the solve's first assembles its matrix H_k as usual and solves H_k p = -g_k by
// conjugate gradients (numerics/pcg.hpp) preconditioned with the solve's last Cholesky factor,
// stopping when the preconditioned residual's size (the error's estimate) is below reuse_tol of
// the step's or a tenth of tol_step, both in the step norm; when reuse_cg CG iterations do not
// get there it factors H_k (which becomes the preconditioner). A reused step whose line search
// finds no decrease is retried with a factorization. The convergence test is unchanged. On the
// README demo's drape the matrix changes too much between iterations for it to pay: a CG
// iteration costs a pair of triangular solves (about a twelfth of a factorization at 16k
// triangles) and in the falling sheet's steps 8 of them missed the tolerance three times in
// four, with more Newton iterations (docs/benchmarks.md, "Drape at 16k triangles").
#include <cmath>
#include <string>

#include "numerics/sparse_cholesky.hpp"
#include "sim/potential.hpp"

namespace yarnhom::sim {

// The simulator's linear solver: the project's one sparse Cholesky (numerics/).
using LinearSolver = numerics::SparseCholesky;
using numerics::parse_solver_kind;
using numerics::SolverKind;

// How a Newton step's size is measured against tol_step. Max: the largest vertex displacement
// (IPC's). MassRms: the mass-weighted root mean square of the vertex displacements,
// sqrt(sum m_i |p_i|^2 / sum m_i), so that in a dynamic step the kinetic energy of the
// remaining correction, 1/2 M_total (|p|_rms / h)^2, is below that of the whole sheet moving
// at tol_step / h. A soft knit's crumples leave a few vertices whose position the energy
// barely fixes (the tables' bending stiffness is ~1e-7 N m); the largest displacement then
// measures those and a step took 26-100 iterations, the mean square measures the motion.
// Auto: the simulation's default, MassRms for dynamic steps and Max for static solves.
enum class StepNorm { Auto, Max, MassRms };
StepNorm parse_step_norm(const std::string& name);  // "auto", "max", "rms"
const char* step_norm_name(StepNorm n);

struct NewtonSettings {
  int max_iterations = 100;
  double tol_step = 0;     // m, the Newton step's size in `norm`; 0: the caller's default
  StepNorm norm = StepNorm::Auto;
  double armijo = 1e-4;
  // The time step's prescribed vertices: false, placed at their targets before the solve;
  // true (the one-solve step), moved within it (newton_minimize's target; sim/integrators.hpp).
  bool prescribed_in_solve = false;
  // Iterations beyond max_iterations, one for each iteration whose line search took less than
  // the whole Newton step (the CCD bound or Armijo cut it short), at most this many: the
  // one-solve step while an obstacle moves (sim/integrators.hpp says why).
  int extra_when_cut = 0;
  // Factor reuse within one solve (above, "Factor reuse"): 0, every iteration factors its own
  // matrix; k > 0, an iteration after the first solves with preconditioned conjugate gradients
  // on its freshly assembled matrix, preconditioned by the solve's last factorization, and
  // factors its own matrix only when k CG iterations do not reach reuse_tol.
  int reuse_cg = 0;
  double reuse_tol = 1e-2;  // CG's stop: the preconditioned residual's step size below reuse_tol times the step's
};

struct NewtonStats {
  int iterations = 0;       // Hessian evaluations and solves
  bool converged = false;
  double energy = 0;
  int shifted = 0;          // factorizations that needed a diagonal shift
  int backtracks = 0;       // line-search halvings
  int extensions = 0;       // line-search doublings past the full step (negative curvature)
  double step_norm = 0;     // the last Newton step's size in the settings' norm
  double shell_energy = NAN;  // E_shell at the returned x (NaN when no pass evaluated it there)
  double t_assemble = 0, t_solve = 0, t_line_search = 0;  // wall seconds
  ShellTimings shell;       // CPU seconds inside the element loop
  bool prescribed_reached = true;  // with a target: the prescribed vertices ended on it
  int factorizations = 0;   // numeric factorizations (each diagonal shift's attempt counts)
  int cg_iterations = 0;    // CG iterations on a reused factor (each: one product with H, one pair of triangular solves)
  int reused = 0;           // iterations whose step came from CG on a reused factor
  int evaluations = 0;      // energy evaluations of the line search and its extension
};

// Minimizes from x (3n; prescribed vertices already at their targets and kept there). The
// hinges' branches S.theta_ref (when set) are carried to each accepted iterate.
//
// target (optional, 3n): the prescribed vertices start where x has them and move to their
// targets within the first iteration, as part of its solve (the one-solve step's handles):
// with d the prescribed move and H the model Hessian at x, the same factorization gives the free
// vertices' response to it, u = -H_ff^-1 H_fp d (the cloth the handle pulls, to first order),
// and the whole move (u, d) is taken by the largest fraction in (0, 1] that CCD allows (colliders
// and contact, 0.9 of the bound when limited) and that keeps the potential finite (halved until
// it is); from there the step goes on as usual: the gradient there, the Newton step on the same
// factorization, the line search. A move cut short leaves prescribed_reached false (the caller
// moves them on in another solve).
NewtonStats newton_minimize(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                            StepState& S, Eigen::VectorXd& x, const NewtonSettings& opt,
                            bool profile = false, const Eigen::VectorXd* target = nullptr);

}  // namespace yarnhom::sim
