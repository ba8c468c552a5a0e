#include "yarn/rve/newton.hpp"

#include "numerics/hessian_factor.hpp"
#include "yarn/rve/rve_ccd.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <vector>

namespace yarnhom::yarn {

using numerics::HessianFactor;

std::string SolveReport::summary() const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s after %d iterations, residual %.3g, energy %.9g J, %.3f s",
                to_string(status), iterations, residual, energy, seconds);
  return buf;
}

double relative_residual(const RveProblem& rve, const Eigen::VectorXd& grad) {
  return numerics::relative_residual(grad, rve.force_scale(), rve.stretch_stiffness());
}

int rve_dense_limit() {
  static const int limit = [] {
    const char* env = std::getenv("YARNHOM_RVE_DENSE_LIMIT");
    if (!env || !*env) return kRveDenseLimit;
    char* end = nullptr;
    const long v = std::strtol(env, &end, 10);
    if (*end != 0 || v < 0 || v > 1000000)
      throw std::invalid_argument(std::string("YARNHOM_RVE_DENSE_LIMIT='") + env + "': expected an integer 0..1000000");
    return static_cast<int>(v);
  }();
  return limit;
}

namespace {

// The energy, gradient and Hessian at (s, st) for H: the triplets as they are for a dense
// factorization (the height term a dense block among them: the assembly of earlier releases,
// bit for bit), the height term apart for a sparse one (`height`).
double evaluate_hessian(const RveProblem& rve, const Strain& s, const RveState& st, Eigen::VectorXd* g,
                        std::vector<Eigen::Triplet<double>>& trip, RveProblem::HeightTerm& height,
                        const HessianFactor& H) {
  trip.clear();
  if (H.dense()) return rve.evaluate(s, st, g, &trip);
  return rve.evaluate_hessian(s, st, g, &trip, &height);
}

void assemble(HessianFactor& H, const std::vector<Eigen::Triplet<double>>& trip, const RveProblem::HeightTerm& height) {
  if (H.dense())
    H.assemble(trip);
  else
    H.assemble(trip, height.U, height.C);
}

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

// One solve (docs/rve.md section 5, newton.hpp): the start, then Newton iterations, each a
// shifted factorization (numerics/newton.hpp), the collision filter and a line search.
class RveNewton {
 public:
  RveNewton(const RveProblem& rve, const Strain& s, RveState& st, const SolveOptions& opt)
      : rve_(rve), s_(s), st_(st), opt_(opt), g_(rve.num_dofs()), d_(rve.num_dofs()),
        H_(rve.num_dofs(), opt.dense_limit >= 0 ? opt.dense_limit : rve_dense_limit(), true),
        dmin_(rve.min_separation()), reach_(2.0 * rve.radius()) {
    // The recorded path is moved out while solving, so that the line search's copies of the
    // state stay cheap.
    path_ = std::move(st_.path);
    st_.path.clear();
    record_ = !path_.empty();
  }

  SolveReport run() {
    if (!start()) return finish(SolveStatus::kInfeasibleStart);
    for (int it = 0;; ++it) {
      const double E = evaluate_hessian(rve_, s_, st_, &g_, trip_, height_, H_);
      rep_.energy = E;
      rep_.residual = relative_residual(rve_, g_);
      rep_.iterations = it;
      if (!std::isfinite(E) || !std::isfinite(rep_.residual)) return finish(SolveStatus::kNonFinite);
      if (opt_.verbose) std::fprintf(stderr, "  newton %3d  E %.12g  residual %.3e  mu %.1e\n", it, E, rep_.residual, mu_);
      if (rep_.residual <= opt_.tolerance) return converged();
      if (it >= opt_.max_iterations) return finish(SolveStatus::kMaxIterations);
      if (opt_.max_seconds > 0 && numerics::seconds_since(t0_) > opt_.max_seconds) return finish(SolveStatus::kTimeLimit);
      assemble(H_, trip_, height_);
      if (!direction()) return finish(SolveStatus::kNonFinite);
      if (!step(E)) {
        // The quadratic model was bad far from the minimum: shift harder (shorter, more
        // gradient-like steps) and try again before giving up.
        if (++rep_.line_search_retries > 8) return finish(SolveStatus::kLineSearchFailed);
        mu_ = numerics::raised_shift(mu_);
        full_step_ = false;
      }
    }
  }

 private:
  SolveReport finish(SolveStatus status) {
    rep_.status = status;
    rep_.seconds = numerics::seconds_since(t0_);
    rep_.cpu_seconds = numerics::thread_cpu_seconds() - c0_;
    rep_.analyses = H_.analyses();
    st_.path = std::move(path_);
    return rep_;
  }

  // An accepted configuration becomes the end of the checked path.
  void reached(const RveState& x) {
    st_.anchor = {s_, x.u};
    if (record_) path_.push_back(st_.anchor);
  }

  // The start: the straight move from the last checked configuration (the anchor: where the
  // previous solve ended, at its strain) to (s, u). A changed start (a predictor) that cannot
  // be reached safely falls back to the anchor's own fluctuations at the new strain; if even
  // that move would bring yarns within d_min, nothing is changed and the caller is told
  // (continuation in smaller strain steps is the cure: produce/first_pass.cpp). false: infeasible.
  bool start() {
    if (static_cast<int>(st_.anchor.u.size()) != rve_.pattern().size())
      throw std::invalid_argument("solve: the state has no anchor configuration (make states with RveProblem::initial_state)");
    if (st_.anchor.s == s_ && st_.anchor.u == st_.u) return true;
    RveState from = st_;
    from.u = st_.anchor.u;
    RveMoveCheck m = check_move(rve_, st_.anchor.s, from, s_, st_, dmin_, reach_);
    if (m.t < 1 && opt_.ccd && st_.u != st_.anchor.u) {
      RveState plain = st_;
      plain.u = st_.anchor.u;
      const RveMoveCheck m2 = check_move(rve_, st_.anchor.s, from, s_, plain, dmin_, reach_);
      if (m2.t >= 1) {
        st_.u = st_.anchor.u;
        m = m2;
        rep_.start_reset = true;
      }
    }
    if (m.t < 1 && opt_.ccd) return false;
    add_move(st_.certificate, m.t, m.end_distance, "start at the new strain");
    reached(st_);
    return true;
  }

  SolveReport converged() {
    if (!opt_.sensitivity_directions.empty()) {
      // Converged before any factorization (a start at the solution): factor here, from the
      // Hessian this iteration's evaluation already assembled.
      if (!factored_) {
        assemble(H_, trip_, height_);
        factored_ = H_.factor(0.0);
      }
      if (factored_) sensitivities(rve_, s_, st_, g_, opt_.sensitivity_directions, H_, rep_);
    }
    st_.certificate.min_distance = std::min(st_.certificate.min_distance, min_separation(rve_, s_, st_, reach_));
    return finish(SolveStatus::kConverged);
  }

  // The Newton direction d_ with the definiteness shift. After a full step try plain Newton
  // first (see newton.hpp), falling back to a tenth of the last shift; otherwise (and after a
  // failed line search, which raised mu) start there. Where plain Newton just failed (an
  // indefinite region) it is tried again only after 1, 2, 4, 8 iterations, so that it does
  // not cost a wasted factorization every iteration. false: no shift worked.
  bool direction() {
    numerics::ShiftSchedule schedule;
    schedule.resume = numerics::relaxed_shift(mu_);
    const bool try_plain = full_step_ && skip_plain_ == 0;
    if (skip_plain_ > 0) --skip_plain_;
    const numerics::ShiftResult shift = numerics::shifted_factorization(
        try_plain ? 0.0 : schedule.resume, [&](double mu) { return numerics::newton_direction(H_, mu, g_, d_); },
        schedule);
    if (!shift.ok) return false;
    if (shift.plain_failed) plain_backoff_ = std::min(2 * plain_backoff_ + 1, 8), skip_plain_ = plain_backoff_;
    mu_ = shift.mu;
    factored_ = true;
    if (mu_ == 0) plain_backoff_ = 0;
    if (mu_ > 0) ++rep_.shifted;
    return true;
  }

  // Along d_ from the state at energy E: the collision filter, Armijo backtracking, the
  // extension of a shifted full step. false: no step length lowers the energy.
  bool step(double E) {
    // The collision filter: the fraction of the full step along which every segment pair
    // stays above d_min (CCD; exact paths, since x is linear in u at fixed s). The line search
    // starts at 0.9 of it (at the fraction itself the barrier is infinite) and only shortens.
    RveState full = st_;
    rve_.apply_step(d_, 1.0, full);
    const RveMoveCheck mc = check_move(rve_, s_, st_, s_, full, dmin_, reach_);
    st_.certificate.min_distance = std::min(st_.certificate.min_distance, mc.start_distance);
    double alpha = 1.0;
    if (mc.t < 1 && opt_.ccd) {
      alpha = 0.9 * mc.t;
      ++rep_.ccd_limited;
    }
    // Armijo backtracking on the energy; once the predicted decrease is at round-off level of
    // E, energy comparisons carry no information: the full Newton step is taken then.
    const double slope = g_.dot(d_);
    RveState trial;
    const numerics::LineSearchResult ls = numerics::armijo_backtracking(E, slope, alpha, [&](double a) {
      trial = st_;
      rve_.apply_step(d_, a, trial);
      return rve_.evaluate(s_, trial, nullptr, nullptr);
    });
    if (!ls.accepted) return false;
    alpha = ls.alpha;
    double Et = ls.energy;
    full_step_ = alpha == 1.0;
    // Where along d the accepted move first comes within d_min (never, with the filter).
    double first_hit = alpha <= mc.t ? std::numeric_limits<double>::infinity() : mc.t;
    if (full_step_ && mu_ > 0) {
      // A shifted step is conservative by design; where the full one was good (near a saddle,
      // escaping along a direction of negative curvature, the shifted steps are tiny and grow
      // only slowly from iteration to iteration) go further while the energy keeps falling and
      // the move stays clear of d_min.
      RveState further;
      RveMoveCheck mx;
      const numerics::Extension x = numerics::extend_step(
          alpha, Et, slope, 12, 1e-4,
          [&](double a) {
            further = st_;
            rve_.apply_step(d_, a, further);
            mx = check_move(rve_, s_, trial, s_, further, dmin_, reach_);
            if (mx.t < 1 && opt_.ccd) return std::numeric_limits<double>::quiet_NaN();
            return rve_.evaluate(s_, further, nullptr, nullptr);
          },
          [&](double a) {
            if (mx.t < 1) first_hit = std::min(first_hit, 0.5 * a * (1 + mx.t));
            trial = std::move(further);
          });
      alpha = x.alpha;
      Et = x.energy;
    }
    st_ = std::move(trial);
    add_move(st_.certificate, first_hit >= alpha ? 1.0 : first_hit / alpha, std::numeric_limits<double>::infinity(),
             "Newton step");
    reached(st_);
    if (opt_.verbose)
      std::fprintf(stderr, "           step %.3g%s  slope %.3e  dE %.3e\n", alpha, mc.t < 1 ? " (collision filter)" : "",
                   slope, Et - E);
    return true;
  }

  const RveProblem& rve_;
  const Strain& s_;
  RveState& st_;
  const SolveOptions& opt_;
  const numerics::SolveClock::time_point t0_ = numerics::SolveClock::now();
  const double c0_ = numerics::thread_cpu_seconds();
  SolveReport rep_;
  Eigen::VectorXd g_, d_;
  std::vector<Eigen::Triplet<double>> trip_;
  RveProblem::HeightTerm height_;
  HessianFactor H_;
  double mu_ = 0.0;
  bool factored_ = false, full_step_ = false;
  int skip_plain_ = 0, plain_backoff_ = 0;
  const double dmin_, reach_;
  std::vector<PathPoint> path_;
  bool record_ = false;
};

}  // namespace

std::vector<Eigen::VectorXd> equilibrium_sensitivity(const RveProblem& rve, const Strain& s, const RveState& st,
                                                     const std::vector<Strain>& directions) {
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd g;
  HessianFactor H(rve.num_dofs(), rve_dense_limit());
  RveProblem::HeightTerm height;
  evaluate_hessian(rve, s, st, &g, trip, height, H);
  assemble(H, trip, height);
  SolveReport rep;
  if (H.factor(0.0)) sensitivities(rve, s, st, g, directions, H, rep);
  return rep.sensitivity;
}

SolveReport solve(const RveProblem& rve, const Strain& s, RveState& st, const SolveOptions& opt) {
  return RveNewton(rve, s, st, opt).run();
}

}  // namespace yarnhom::yarn
