#pragma once
// Newton's method for a yarn strip's equilibrium (the clamps where they are), two ways:
//
// - trust region (the default, strip_solve_trust.cpp): Steihaug-CG on the exact Hessian,
//   preconditioned by the Cholesky factor of the projected Hessian (every element's Hessian
//   made positive semi-definite), the radius adapted to the ratio of actual to predicted
//   decrease; it follows the negative curvature of the soft directions a stretched strip has
//   near its equilibrium instead of creeping along them;
// - switched (strip_solve.cpp, the first method, kept for comparison): the RVE's algorithm
//   (numerics/newton.hpp: definiteness shift, Armijo backtracking, step extension) on a
//   projected model far from equilibrium and the exact one near it.
//
// Both use the RVE's relative residual and its collision filter (every step is shortened to
// 0.9 of the fraction of it that CCD finds safe, and every accepted step is added to the
// state's certificate), and a sparse Newton system (CHOLMOD supernodal above `dense_limit`
// unknowns).
#include <string>

#include "numerics/newton.hpp"
#include "yarn/strip/strip_problem.hpp"

namespace yarnhom::yarn {

using numerics::SolveStatus;
using numerics::to_string;

struct StripSolveOptions {
  double tolerance = 1e-10;  // relative residual, as the RVE's SolveOptions::tolerance
  int max_iterations = 200;
  int dense_limit = 300;     // unknowns up to which the Newton system is factored densely
  bool verbose = false;      // one line per iteration on stderr
  // The Newton method (docs/strip.md section 4): kTrustRegion, Steihaug-CG on the exact
  // Hessian preconditioned by the projected one's Cholesky factor (strip_solve_trust.cpp);
  // kSwitched, line searches on the projected or the exact model, switched (the first
  // method, kept for comparison: docs/benchmarks.md).
  enum class Method { kTrustRegion, kSwitched } method = Method::kTrustRegion;
  // Trust region: iterations without halving the residual after which the switched method
  // finishes the solve (also when the radius collapses below 1e-6 of the first).
  int trust_stall_iterations = 120;
};

// The fields every Newton solve reports (numerics::NewtonReport: status, iterations, residual,
// energy, seconds, analyses, shifted, line_search_retries), and the strip's own.
struct StripSolveReport : numerics::NewtonReport {
  double assembly_seconds = 0;    // energy, gradient and Hessian assemblies
  double factor_seconds = 0;      // Cholesky factorizations (symbolic analyses included)
  double line_search_seconds = 0; // energy evaluations and step filter of the line searches
  int filtered = 0;               // iterations whose step the filter shortened
  bool fallback = false;          // the trust region stalled and the switched method finished
  std::string summary() const;
};

double strip_residual(const StripProblem& P, const Eigen::VectorXd& grad);

// Minimizes the energy over the unknowns from `st`, which holds the result on return
// whatever the status, by opt.method.
StripSolveReport solve_strip(const StripProblem& P, StripState& st, const StripSolveOptions& opt = {});
StripSolveReport solve_strip_switched(const StripProblem& P, StripState& st, const StripSolveOptions& opt);
StripSolveReport solve_strip_trust(const StripProblem& P, StripState& st, const StripSolveOptions& opt);

}  // namespace yarnhom::yarn
