#include "numerics/newton.hpp"

#include <time.h>

#include <cmath>

namespace yarnhom::numerics {

const char* to_string(SolveStatus s) {
  switch (s) {
    case SolveStatus::kConverged: return "converged";
    case SolveStatus::kMaxIterations: return "max_iterations";
    case SolveStatus::kLineSearchFailed: return "line_search_failed";
    case SolveStatus::kNonFinite: return "non_finite";
    case SolveStatus::kInfeasibleStart: return "infeasible_start";
    case SolveStatus::kTimeLimit: return "time_limit";
  }
  return "unknown";
}

double seconds_since(SolveClock::time_point t) {
  return std::chrono::duration<double>(SolveClock::now() - t).count();
}

double thread_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double relative_residual(const Eigen::VectorXd& g, const Eigen::VectorXd& scale, double stiffness) {
  if (g.size() == 0) return 0.0;
  const double rms = g.cwiseProduct(scale).norm() / std::sqrt(double(g.size()));
  return rms / stiffness;
}

ShiftResult shifted_factorization(double start, const std::function<bool(double)>& attempt,
                                  const ShiftSchedule& schedule) {
  ShiftResult r;
  r.mu = start;
  for (;;) {
    ++r.attempts;
    if (attempt(r.mu)) {
      r.ok = true;
      return r;
    }
    if (r.attempts >= schedule.max_attempts) return r;
    if (r.mu == 0) r.plain_failed = true;
    if (r.mu == 0 && schedule.resume > 0) {
      r.mu = schedule.resume;  // plain Newton failed: go on from the caller's last shift
    } else {
      r.mu = r.mu == 0 ? schedule.first : r.mu * schedule.growth;
    }
  }
}

bool newton_direction(HessianFactor& H, double mu, const Eigen::VectorXd& g, Eigen::VectorXd& d) {
  if (!H.factor(mu)) return false;
  d = H.solve(-g);
  return d.allFinite() && g.dot(d) < 0;
}

LineSearchResult armijo_backtracking(double E, double slope, double alpha0, const std::function<double(double)>& energy,
                                     const LineSearchOptions& opt) {
  LineSearchResult r;
  r.alpha = alpha0;
  const bool roundoff = opt.roundoff > 0 && -slope < opt.roundoff * std::abs(E);
  for (int k = 0; k < opt.max_trials; ++k) {
    r.energy = energy(r.alpha);
    ++r.trials;
    if (std::isfinite(r.energy) && (r.energy <= E + opt.c * r.alpha * slope || roundoff)) {
      r.accepted = true;
      return r;
    }
    r.alpha *= 0.5;
  }
  return r;
}

Extension extend_step(double alpha, double Et, double slope, int max_doublings, double c,
                      const std::function<double(double)>& energy, const std::function<void(double)>& taken) {
  Extension x{alpha, Et, 0};
  for (int k = 0; k < max_doublings; ++k) {
    const double Ef = energy(2 * x.alpha);
    const double bound = c == 0 ? x.energy : x.energy + c * x.alpha * slope;
    if (!(std::isfinite(Ef) && Ef < bound)) break;
    x.alpha *= 2;
    x.energy = Ef;
    ++x.doublings;
    if (taken) taken(x.alpha);
  }
  return x;
}

}  // namespace yarnhom::numerics
