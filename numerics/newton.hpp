#pragma once
// The pieces of Newton's method that every solver of the project shares (the yarn RVE,
// yarn/rve/newton.cpp; the yarn strips, yarn/strip/strip_solve*.cpp; written so that the
// shell simulator's loop, sim/newton.cpp, can use them too):
//
// - the solve's status and the report fields every solver fills (NewtonReport);
// - the relative residual: the RMS of a scaled gradient over a stiffness;
// - the factorization with a growing diagonal shift (shifted_factorization): a matrix that is
//   not positive definite (an indefinite Hessian away from a minimum, a singular one) is
//   factored again with a shift mu, from the caller's start, then `first` growing by `growth`
//   per failure; what "factor with shift mu" means is the caller's (HessianFactor's
//   H + mu diag(|H_ii|), or the simulator's multiple of the mean diagonal);
// - the Newton direction from a HessianFactor, accepted when finite and a descent direction;
// - Armijo backtracking on the energy along a direction (halving from a start step);
// - the extension of an accepted full step by doubling while the energy keeps falling.
//
// The loops around them (what is assembled, the collision filter, when to try plain Newton)
// stay with each solver; these are the arithmetic that must be the same everywhere.
#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <functional>

#include "numerics/hessian_factor.hpp"

namespace yarnhom::numerics {

// kInfeasibleStart: a solver whose start must be reachable (the RVE's collision-checked move
// to a new strain) could not reach it; the state is left unchanged. kTimeLimit: a wall-clock
// guard stopped the solve.
enum class SolveStatus { kConverged, kMaxIterations, kLineSearchFailed, kNonFinite, kInfeasibleStart,
                         kTimeLimit };
const char* to_string(SolveStatus s);

// What every Newton solve reports; each solver's report adds its own fields.
struct NewtonReport {
  SolveStatus status = SolveStatus::kMaxIterations;
  int iterations = 0;
  double residual = 0;   // relative residual at the end (relative_residual)
  double energy = 0;     // J
  double seconds = 0;    // wall time
  int analyses = 0;      // symbolic factorizations done
  int shifted = 0;       // iterations that needed the definiteness shift
  int line_search_retries = 0;  // line searches that failed and were retried
  bool converged() const { return status == SolveStatus::kConverged; }
};

using SolveClock = std::chrono::steady_clock;
// Wall seconds since t.
double seconds_since(SolveClock::time_point t);
// CPU seconds of the calling thread (what a loaded machine does not inflate).
double thread_cpu_seconds();

// rms(g_i * scale_i) / stiffness: unbalanced force per unknown relative to a stiffness (the
// yarn solvers: scale 1 for positions and 1/r for twist angles, stiffness EA). 0 for no unknowns.
double relative_residual(const Eigen::VectorXd& g, const Eigen::VectorXd& scale, double stiffness);

// The growing diagonal shift. attempt(mu) factors the matrix shifted by mu (and may check
// more, such as a descent direction); on failure the next mu is `resume` after a failed
// mu = 0 when resume > 0, else `first` after 0, else growth * mu; at most max_attempts
// attempts in all. The yarn solvers: HessianFactor::factor(mu), 42 attempts, resume = the RVE's
// last shift / 10 (relaxed_shift). The simulator's schedule is the same with 13 attempts (the
// unshifted one and 12 more), its attempt adding the increment of mu times the mean diagonal.
struct ShiftSchedule {
  double first = 1e-8;
  double growth = 10;
  int max_attempts = 42;
  double resume = 0;
};
struct ShiftResult {
  bool ok = false;            // an attempt succeeded
  double mu = 0;              // its shift (the last one tried when none did)
  int attempts = 0;
  bool plain_failed = false;  // mu = 0 was tried and failed
};
ShiftResult shifted_factorization(double start, const std::function<bool(double mu)>& attempt,
                                  const ShiftSchedule& schedule = {});
// The yarn solvers' policy between iterations: the next one starts at a tenth of the last
// shift (0 once that falls below 1e-8: plain Newton near the minimum); a failed line search
// raises it a hundredfold, to at least 1e-3.
inline double relaxed_shift(double mu) { return mu < 1e-7 ? 0.0 : mu / 10; }
inline double raised_shift(double mu) { return std::max(mu * 100, 1e-3); }

// Factors H + mu diag(|H_ii|) and solves d = -(H + mu diag)^-1 g: true when the factorization
// succeeded and d is finite and a descent direction (g.d < 0).
bool newton_direction(HessianFactor& H, double mu, const Eigen::VectorXd& g, Eigen::VectorXd& d);

// Armijo backtracking along a direction with slope g.d < 0 from energy E: energy(alpha) is the
// energy at x + alpha d (the caller keeps what it evaluated: the accepted trial is the last
// one); a trial is accepted when finite and E(alpha) <= E + c alpha slope, or, with
// roundoff > 0, when the predicted decrease -slope is below roundoff |E| (energy differences
// are round-off there: the step is taken). alpha starts at alpha0 and halves after each
// rejected trial, at most max_trials trials.
struct LineSearchOptions {
  double c = 1e-4;
  int max_trials = 40;
  double roundoff = 1e-13;  // 0: no round-off acceptance
};
struct LineSearchResult {
  bool accepted = false;
  double alpha = 0;   // the accepted step; when none was, the start halved max_trials times
  double energy = 0;  // the energy at the accepted step (the last trial's otherwise)
  int trials = 0;     // energies evaluated
};
LineSearchResult armijo_backtracking(double E, double slope, double alpha0, const std::function<double(double alpha)>& energy,
                                     const LineSearchOptions& opt = {});

// (The simulator's search: start at the collider-limited step, roundoff = 0; its extension
// below: at most 4 doublings (16x), c = 0, a move beyond the colliders' bound non-finite.)

// Extension of an accepted step alpha (energy Et) past it: 2 alpha is tried (energy(2 alpha);
// a non-finite value, such as a move the caller does not allow, stops it) and taken while its
// energy is below Et + c alpha slope (c = 0: below Et), then 4 alpha, ..., at most
// max_doublings times; taken(alpha) is called with each new step taken (the last energy
// evaluated is the one taken). For a conservative step (a shifted or projected Hessian) that
// was good in full: near a saddle or past negative curvature such steps are too short.
struct Extension {
  double alpha = 0, energy = 0;
  int doublings = 0;
};
Extension extend_step(double alpha, double Et, double slope, int max_doublings, double c,
                      const std::function<double(double alpha)>& energy,
                      const std::function<void(double alpha)>& taken = {});

}  // namespace yarnhom::numerics
