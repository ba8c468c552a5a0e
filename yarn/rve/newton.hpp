#pragma once
// Newton's method with a backtracking line search for the RVE equilibrium at a strain s.
//
// Each iteration assembles the exact Hessian in the reduced unknowns and factors it by
// Cholesky (numerics/hessian_factor.hpp: dense up to rve_dense_limit() unknowns, sparse beyond,
// with the height term apart and a pattern that only grows within a solve; the shift, line
// search and step extension are numerics/newton.hpp's). Definiteness fix: when the factorization fails or has a non-positive pivot (the
// Hessian is indefinite away from a minimum), the diagonal is raised to H + mu diag(|H_ii|)
// with mu growing tenfold until the factorization is positive definite (a Levenberg-style
// shift, scale-free because it is relative to each dof's own stiffness). After a full step
// (alpha = 1, the quadratic model was good) the next iteration first tries the unshifted
// Hessian: a shift that merely decays tenfold per iteration would turn the quadratic
// convergence near the minimum into linear convergence at rate ~mu (measured: 3-4 extra
// iterations per solve). Otherwise mu starts at a tenth of the last one used. The step then decreases the energy
// (Armijo backtracking); when no step length decreases it, the shift is raised (at least to
// 1e-3, a hundredfold) and the iteration repeated, up to 8 times. Convergence: the residual, the RMS of the gradient with twist
// moments divided by the yarn radius (forces), relative to the stretching stiffness EA,
// falls below `tolerance`. The rods' reference frames stay fixed (FrameState in rve.hpp).
#include <string>
#include <vector>

#include "numerics/newton.hpp"
#include "yarn/rve/rve.hpp"

namespace yarnhom::yarn {

struct SolveOptions {
  double tolerance = 1e-10;  // on the relative residual (see above)
  int max_iterations = 200;
  // Wall-clock guard (s; 0: none): a solve still running after this long stops with
  // kTimeLimit, so that a pathological input is refused in bounded time whatever an
  // iteration costs.
  double max_seconds = 0;
  bool verbose = false;      // one line per iteration on stderr
  // Strain directions whose equilibrium sensitivities du/dt (t the coordinate along the
  // direction) the solve returns on convergence, for a continuation predictor (see
  // SolveReport::sensitivity). Empty: none computed.
  std::vector<Strain> sensitivity_directions;
  // The collision filter (docs/rve.md section 5): every step is shortened so that no segment
  // pair comes within d_min along it (CCD). false: unfiltered steps, for comparisons and
  // tests only; moves are still checked and a state that passed within d_min is marked in
  // its certificate.
  bool ccd = true;
  // The largest number of unknowns factored densely; -1: rve_dense_limit() (below). Both paths
  // give the same steps to round-off (tests compare them).
  int dense_limit = -1;
};

// The largest RVE factored densely (Eigen's LLT); beyond it CHOLMOD with the height term by
// Woodbury (numerics/hessian_factor.hpp). Both give the same Newton steps to round-off; the
// sparse one wins from about this size on (docs/benchmarks.md, "Patch RVEs": even at 310 and
// 396 unknowns the two are within 10 %, at 722 the sparse one is 1.3x faster, at 1418 2.4x).
// The paper's stockinette and basket tiles stay dense, the honeycomb and cartridge belt rib
// tiles and every 2 x 2 patch are sparse. The environment variable YARNHOM_RVE_DENSE_LIMIT
// overrides it (for comparisons; read once per process).
constexpr int kRveDenseLimit = 500;
int rve_dense_limit();

// The status (numerics/newton.hpp). kInfeasibleStart: the straight move from the state's last
// checked configuration to the start at the new strain would bring yarn segments within d_min
// (a strain step too large for the configuration: solve in smaller strain steps); the state is
// left unchanged.
using numerics::SolveStatus;
using numerics::to_string;

// The fields every Newton solve reports (numerics::NewtonReport: status, iterations, residual,
// energy, seconds, analyses, shifted, line_search_retries), and the RVE's own.
struct SolveReport : numerics::NewtonReport {
  double cpu_seconds = 0; // CPU time of the calling thread (what a loaded machine does not inflate)
  int ccd_limited = 0;   // iterations whose step the collision filter shortened
  bool start_reset = false;  // the given start was not safely reachable; the anchor's u was used
  // On convergence, per SolveOptions::sensitivity_directions D: the first-order change of the
  // equilibrium unknowns (reduced, as RveProblem::apply_step takes them) per unit t along D,
  // from differentiating g(u(t), s + t D) = 0:  H du/dt = -(dg/ds) D. H is the last Newton
  // factorization (one step before the solution: accurate to the last step's size, plenty for
  // a predictor), dg/ds D a forward difference of the gradient (step 1e-7 in t). Empty when
  // not converged.
  std::vector<Eigen::VectorXd> sensitivity;
  std::string summary() const;
};

// Relative residual of a reduced gradient (see above).
double relative_residual(const RveProblem& rve, const Eigen::VectorXd& grad);

// Minimizes the energy at s starting from `state` (any state: cold from the pattern or warm
// from a neighbouring strain), which holds the result on return whatever the status.
SolveReport solve(const RveProblem& rve, const Strain& s, RveState& state, const SolveOptions& opt = {});

// The sensitivities of SolveReport::sensitivity for an equilibrium `state` at s, with the
// Hessian assembled and factored here (for states that did not come out of a solve, such as
// the rest state shared by every term). Empty if the factorization fails.
std::vector<Eigen::VectorXd> equilibrium_sensitivity(const RveProblem& rve, const Strain& s, const RveState& state,
                                                     const std::vector<Strain>& directions);

}  // namespace yarnhom::yarn
