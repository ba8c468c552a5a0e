#include "yarn/newton.hpp"

#include "yarn/hessian_factor.hpp"
#include "yarn/rve_ccd.hpp"

#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <vector>

namespace yarnhom::yarn {

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

std::string SolveReport::summary() const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s after %d iterations, residual %.3g, energy %.9g J, %.3f s",
                to_string(status), iterations, residual, energy, seconds);
  return buf;
}

double relative_residual(const RveProblem& rve, const Eigen::VectorXd& grad) {
  if (grad.size() == 0) return 0.0;
  const double rms = grad.cwiseProduct(rve.force_scale()).norm() / std::sqrt(double(grad.size()));
  return rms / rve.stretch_stiffness();
}

namespace {

// SolveReport::sensitivity: H du/dt = -(dg/ds) D for every direction D, with a factorization
// of the Hessian at (or, from the last Newton iteration, next to) the solution; g the
// gradient there.
void sensitivities(const RveProblem& rve, const Strain& s, const RveState& st, const Eigen::VectorXd& g,
                   const std::vector<Strain>& directions, const HessianFactor& factor, SolveReport& rep) {
  constexpr double h = 1e-7;
  Eigen::VectorXd gp;
  rep.sensitivity.clear();
  for (const Strain& D : directions) {
    rve.evaluate(s + h * D, st, &gp);
    Eigen::VectorXd du = factor.solve(-(gp - g) / h);
    if (!du.allFinite()) du.setZero();
    rep.sensitivity.push_back(std::move(du));
  }
}

double thread_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
}  // namespace

std::vector<Eigen::VectorXd> equilibrium_sensitivity(const RveProblem& rve, const Strain& s, const RveState& st,
                                                     const std::vector<Strain>& directions) {
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd g;
  rve.evaluate(s, st, &g, &trip);
  HessianFactor H(rve.num_dofs());
  H.assemble(trip);
  SolveReport rep;
  if (H.factor(0.0)) sensitivities(rve, s, st, g, directions, H, rep);
  return rep.sensitivity;
}

SolveReport solve(const RveProblem& rve, const Strain& s, RveState& st, const SolveOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = thread_cpu_seconds();
  SolveReport rep;
  const int N = rve.num_dofs();
  Eigen::VectorXd g(N), d(N);
  std::vector<Eigen::Triplet<double>> trip;
  HessianFactor H(N);
  double mu = 0.0;
  bool factored = false, full_step = false;
  int skip_plain = 0, plain_backoff = 0;
  const double dmin = rve.min_separation(), reach = 2.0 * rve.radius();
  // The recorded path is moved out while solving, so that the line search's copies of the
  // state stay cheap.
  std::vector<PathPoint> path = std::move(st.path);
  st.path.clear();
  const bool record = !path.empty();
  auto finish = [&](SolveStatus status) {
    rep.status = status;
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rep.cpu_seconds = thread_cpu_seconds() - c0;
    rep.analyses = H.analyses();
    st.path = std::move(path);
    return rep;
  };
  // An accepted configuration becomes the end of the checked path.
  auto reached = [&](const RveState& x) {
    st.anchor = {s, x.u};
    if (record) path.push_back(st.anchor);
  };

  // The start: the straight move from the last checked configuration (the anchor: where the
  // previous solve ended, at its strain) to (s, u). A changed start (a predictor) that cannot
  // be reached safely falls back to the anchor's own fluctuations at the new strain; if even
  // that move would bring yarns within d_min, nothing is changed and the caller is told
  // (continuation in smaller strain steps is the cure: yarn/produce.cpp).
  if (static_cast<int>(st.anchor.u.size()) != rve.pattern().size())
    throw std::invalid_argument("solve: the state has no anchor configuration (make states with RveProblem::initial_state)");
  if (!(st.anchor.s == s && st.anchor.u == st.u)) {
    RveState from = st;
    from.u = st.anchor.u;
    RveMoveCheck m = check_move(rve, st.anchor.s, from, s, st, dmin, reach);
    if (m.t < 1 && opt.ccd && st.u != st.anchor.u) {
      RveState plain = st;
      plain.u = st.anchor.u;
      const RveMoveCheck m2 = check_move(rve, st.anchor.s, from, s, plain, dmin, reach);
      if (m2.t >= 1) {
        st.u = st.anchor.u;
        m = m2;
        rep.start_reset = true;
      }
    }
    if (m.t < 1 && opt.ccd) return finish(SolveStatus::kInfeasibleStart);
    add_move(st.certificate, m.t, m.end_distance, "start at the new strain");
    reached(st);
  }

  for (int it = 0;; ++it) {
    trip.clear();
    const double E = rve.evaluate(s, st, &g, &trip);
    rep.energy = E;
    rep.residual = relative_residual(rve, g);
    rep.iterations = it;
    if (!std::isfinite(E) || !std::isfinite(rep.residual)) return finish(SolveStatus::kNonFinite);
    if (opt.verbose) std::fprintf(stderr, "  newton %3d  E %.12g  residual %.3e  mu %.1e\n", it, E, rep.residual, mu);
    if (rep.residual <= opt.tolerance) {
      if (!opt.sensitivity_directions.empty()) {
        // Converged before any factorization (a start at the solution): factor here, from the
        // Hessian this iteration's evaluation already assembled.
        if (!factored) {
          H.assemble(trip);
          factored = H.factor(0.0);
        }
        if (factored) sensitivities(rve, s, st, g, opt.sensitivity_directions, H, rep);
      }
      st.certificate.min_distance = std::min(st.certificate.min_distance, min_separation(rve, s, st, reach));
      return finish(SolveStatus::kConverged);
    }
    if (it >= opt.max_iterations) return finish(SolveStatus::kMaxIterations);
    if (opt.max_seconds > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > opt.max_seconds)
      return finish(SolveStatus::kTimeLimit);

    H.assemble(trip);
    // After a full step try plain Newton first (see newton.hpp), falling back to a tenth of
    // the last shift; otherwise (and after a failed line search, which raised mu) start there.
    // Where plain Newton just failed (an indefinite region) it is tried again only after
    // 1, 2, 4, 8 iterations, so that it does not cost a wasted factorization every iteration.
    const double resume = mu < 1e-7 ? 0.0 : mu / 10;
    const bool try_plain = full_step && skip_plain == 0;
    if (skip_plain > 0) --skip_plain;
    mu = try_plain ? 0.0 : resume;
    for (int tries = 0;; ++tries) {
      bool ok = H.factor(mu);
      if (ok) {
        d = H.solve(-g);
        ok = d.allFinite() && g.dot(d) < 0;
      }
      if (ok) break;
      if (tries > 40) return finish(SolveStatus::kNonFinite);
      if (mu == 0) plain_backoff = std::min(2 * plain_backoff + 1, 8), skip_plain = plain_backoff;
      if (mu == 0 && resume > 0) {
        mu = resume;  // plain Newton failed: go on from the last shift
      } else {
        mu = mu == 0 ? 1e-8 : mu * 10;
      }
    }
    factored = true;
    if (mu == 0) plain_backoff = 0;
    if (mu > 0) ++rep.shifted;

    // The collision filter: the fraction of the full step along which every segment pair
    // stays above d_min (CCD; exact paths, since x is linear in u at fixed s). The line search
    // starts at 0.9 of it (at the fraction itself the barrier is infinite) and only shortens.
    RveState full = st;
    rve.apply_step(d, 1.0, full);
    const RveMoveCheck mc = check_move(rve, s, st, s, full, dmin, reach);
    st.certificate.min_distance = std::min(st.certificate.min_distance, mc.start_distance);
    double alpha = 1.0;
    if (mc.t < 1 && opt.ccd) {
      alpha = 0.9 * mc.t;
      ++rep.ccd_limited;
    }

    // Armijo backtracking on the energy. Once the predicted decrease is at round-off level of
    // E, energy comparisons carry no information: the full Newton step is taken then.
    const double slope = g.dot(d);
    bool accepted = false;
    for (int ls = 0; ls < 40; ++ls) {
      RveState trial = st;
      rve.apply_step(d, alpha, trial);
      double Et = rve.evaluate(s, trial, nullptr, nullptr);
      if (std::isfinite(Et) && (Et <= E + 1e-4 * alpha * slope || -slope < 1e-13 * std::abs(E))) {
        full_step = alpha == 1.0;
        // Where along d the accepted move first comes within d_min (never, with the filter).
        double first_hit = alpha <= mc.t ? std::numeric_limits<double>::infinity() : mc.t;
        if (full_step && mu > 0) {
          // A shifted step is conservative by design; where the full one was good (near a
          // saddle, escaping along a direction of negative curvature, the shifted steps are
          // tiny and grow only slowly from iteration to iteration) go further while the
          // energy keeps falling and the move stays clear of d_min.
          for (int ex = 0; ex < 12; ++ex) {
            RveState further = st;
            rve.apply_step(d, 2 * alpha, further);
            const RveMoveCheck mx = check_move(rve, s, trial, s, further, dmin, reach);
            if (mx.t < 1 && opt.ccd) break;
            const double Ef = rve.evaluate(s, further, nullptr, nullptr);
            if (!(std::isfinite(Ef) && Ef < Et + 1e-4 * alpha * slope)) break;
            if (mx.t < 1) first_hit = std::min(first_hit, alpha * (1 + mx.t));
            alpha *= 2;
            trial = std::move(further);
            Et = Ef;
          }
        }
        st = std::move(trial);
        add_move(st.certificate, first_hit >= alpha ? 1.0 : first_hit / alpha, std::numeric_limits<double>::infinity(),
                 "Newton step");
        reached(st);
        accepted = true;
        if (opt.verbose)
          std::fprintf(stderr, "           step %.3g%s  slope %.3e  dE %.3e\n", alpha,
                       mc.t < 1 ? " (collision filter)" : "", slope, Et - E);
        break;
      }
      alpha *= 0.5;
    }
    if (!accepted) {
      // The quadratic model was bad far from the minimum: shift harder (shorter, more
      // gradient-like steps) and try again before giving up.
      if (++rep.line_search_retries > 8) return finish(SolveStatus::kLineSearchFailed);
      mu = std::max(mu * 100, 1e-3);
      full_step = false;
      continue;
    }
  }
}

}  // namespace yarnhom::yarn
