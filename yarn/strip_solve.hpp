#pragma once
// Newton's method for a yarn strip's equilibrium (the clamps where they are). The same
// algorithm as the RVE's (yarn/newton.hpp: exact Hessian, definiteness shift
// H + mu diag(|H_ii|) raised tenfold until Cholesky succeeds, plain Newton retried after full
// steps, Armijo backtracking, shift raised when no step decreases the energy; the same
// relative residual; the RVE's collision filter: every line search starts at 0.9 of the
// fraction of the step that CCD finds safe, and every accepted step is added to the state's
// certificate), with two differences for a strip: a projected model far from equilibrium
// (below), and a sparse Newton system (CHOLMOD supernodal above `dense_limit` unknowns).
#include <string>

#include "yarn/newton.hpp"
#include "yarn/strip_problem.hpp"

namespace yarnhom::yarn {

struct StripSolveOptions {
  double tolerance = 1e-10;  // relative residual, as SolveOptions::tolerance
  int max_iterations = 200;
  int dense_limit = 300;     // unknowns up to which the Newton system is factored densely
  bool verbose = false;      // one line per iteration on stderr
};

struct StripSolveReport {
  SolveStatus status = SolveStatus::kMaxIterations;
  int iterations = 0;
  double residual = 0, energy = 0;
  double seconds = 0;             // wall time of the solve
  double assembly_seconds = 0;    // energy, gradient and Hessian assemblies
  double factor_seconds = 0;      // Cholesky factorizations (symbolic analyses included)
  double line_search_seconds = 0; // energy evaluations and step filter of the line searches
  int analyses = 0;               // symbolic analyses (sparse pattern changed)
  int shifted = 0;                // iterations that needed the definiteness shift
  int filtered = 0;               // iterations whose step the filter shortened
  int line_search_retries = 0;
  bool converged() const { return status == SolveStatus::kConverged; }
  std::string summary() const;
};

double strip_residual(const StripProblem& P, const Eigen::VectorXd& grad);

// Minimizes the energy over the unknowns from `st`, which holds the result on return
// whatever the status.
StripSolveReport solve_strip(const StripProblem& P, StripState& st, const StripSolveOptions& opt = {});

}  // namespace yarnhom::yarn
