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
#include "numerics/sparse_cholesky.hpp"
#include "sim/potential.hpp"

namespace yarnhom::sim {

// The simulator's linear solver: the project's one sparse Cholesky (numerics/).
using LinearSolver = numerics::SparseCholesky;
using numerics::parse_solver_kind;
using numerics::SolverKind;

struct NewtonSettings {
  int max_iterations = 100;
  double tol_step = 0;     // m, infinity norm of the Newton step; 0: the caller's default
  double armijo = 1e-4;
};

struct NewtonStats {
  int iterations = 0;       // Hessian evaluations and solves
  bool converged = false;
  double energy = 0;
  int shifted = 0;          // factorizations that needed a diagonal shift
  int backtracks = 0;       // line-search halvings
  int extensions = 0;       // line-search doublings past the full step (negative curvature)
  double step_norm = 0;     // infinity norm of the last Newton step
  double t_assemble = 0, t_solve = 0, t_line_search = 0;  // wall seconds
  ShellTimings shell;       // CPU seconds inside the element loop
};

// Minimizes from x (3n; prescribed vertices already at their targets and kept there).
NewtonStats newton_minimize(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                            const StepState& S, Eigen::VectorXd& x, const NewtonSettings& opt,
                            bool profile = false);

}  // namespace yarnhom::sim
