#include "yarn/strip/strip_solve.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "numerics/hessian_factor.hpp"
#include "yarn/strip/strip_newton.hpp"

namespace yarnhom::yarn {

using numerics::BlockHessian;
using numerics::HessianFactor;
using numerics::seconds_since;
using numerics::SolveClock;

std::string StripSolveReport::summary() const {
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "%s after %d iterations, residual %.3g, energy %.9g J, %.2f s (assembly %.2f, factor %.2f, "
                "line search %.2f; %d symbolic analyses)%s",
                to_string(status), iterations, residual, energy, seconds, assembly_seconds, factor_seconds,
                line_search_seconds, analyses, fallback ? ", trust region stalled: finished by the switched method" : "");
  return buf;
}

double strip_residual(const StripProblem& P, const Eigen::VectorXd& g) {
  return numerics::relative_residual(g, P.force_scale(), P.stretch_stiffness());
}

StripSolveReport solve_strip(const StripProblem& P, StripState& st, const StripSolveOptions& opt) {
  return opt.method == StripSolveOptions::Method::kTrustRegion ? solve_strip_trust(P, st, opt)
                                                               : solve_strip_switched(P, st, opt);
}

namespace {

// The switched method. Two models of the energy: `exact` (its Hessian) and projected (every
// element's Hessian made positive semi-definite). Far from equilibrium the exact Hessian of a
// strip is strongly indefinite (soft boundary yarn pressed by contact: measured scaled
// eigenvalues down to -31), and a diagonal shift large enough to fix that makes every step
// tiny; the projected model gives descent steps of the right size. Close to equilibrium the
// exact Hessian is positive definite and converges quadratically: after each full projected
// step the exact one is tried, and where it is not positive definite the solve goes back to
// projected steps for 1, 2, 4, 8 iterations (as the RVE's solve backs off plain Newton).
// The exact model comes in two strengths: the exact Hessian itself (quadratic convergence),
// and one whose boundary-yarn joints are projected (StripProblem::Projection): the soft
// twist of those joints is often the only indefinite part near a solution (measured on a
// stretched stockinette strip), but a model that drops curvature converges only linearly
// (measured on a stocktiny wale strip: residual ratio 0.98 per iteration, 300 iterations at
// 1e-9). So the exact Hessian is tried first; where it is not positive definite the partly
// projected one is used, and the exact one is tried again as soon as steps of the partly
// projected model stop reducing the residual fourfold per iteration.
class SwitchedNewton : StripNewton {
 public:
  using Projection = StripProblem::Projection;

  SwitchedNewton(const StripProblem& P, StripState& st, const StripSolveOptions& opt)
      : StripNewton(P, st, opt), d_(P.num_dofs()), H_(P.num_dofs(), opt.dense_limit) {}

  StripSolveReport run() {
    for (int it = 0;; ++it) {
      auto ta = SolveClock::now();
      model_ = !exact_ ? Projection::kAll : exact_none_ ? Projection::kNone : Projection::kBoundaryJoints;
      const double E = P_.evaluate(st_, &g_, &B_, nullptr, nullptr, model_);
      if (!record(it, E)) return finish(SolveStatus::kNonFinite);
      // The partly projected model converging slowly: the exact one is tried at the next iteration.
      if (step_model_ == Projection::kBoundaryJoints && rep_.residual > 0.25 * previous_residual_) exact_none_ = true;
      previous_residual_ = rep_.residual;
      if (opt_.verbose)
        std::fprintf(stderr, "  newton %3d  E %.12g  residual %.3e  %s\n", it, E, rep_.residual,
                     model_ == Projection::kAll    ? "projected"
                     : model_ == Projection::kNone ? "exact"
                                                   : "exact (boundary joints projected)");
      if (rep_.residual <= opt_.tolerance) {
        converged(ta);
        return finish(SolveStatus::kConverged);
      }
      if (it >= opt_.max_iterations) return finish(SolveStatus::kMaxIterations);
      H_.assemble(B_.matrix());
      rep_.assembly_seconds += seconds_since(ta);
      if (!direction()) return finish(SolveStatus::kNonFinite);
      if (!step(E)) {
        if (++rep_.line_search_retries > 8) return finish(SolveStatus::kLineSearchFailed);
        mu_ = numerics::raised_shift(mu_);
        exact_ = false;
        continue;
      }
      mu_ = numerics::relaxed_shift(mu_);
      switch_model();
    }
  }

 private:
  StripSolveReport finish(SolveStatus status) { return StripNewton::finish(status, H_.analyses()); }

  // Reassembles the Hessian of model m into H_ (the time so far counted as factorization).
  void reassemble(Projection m, SolveClock::time_point& tf) {
    rep_.factor_seconds += seconds_since(tf);
    const auto ta = SolveClock::now();
    P_.evaluate(st_, &g_, &B_, nullptr, nullptr, m);
    H_.assemble(B_.matrix());
    rep_.assembly_seconds += seconds_since(ta);
    tf = SolveClock::now();
  }

  // The Newton direction d_: the exact model's (plain Newton) where it is positive definite,
  // else the projected model's with the definiteness shift (numerics/newton.hpp) where it is
  // singular or a line search failed. false: no shift worked.
  bool direction() {
    auto tf = SolveClock::now();
    bool have_step = false;
    if (exact_) {
      have_step = numerics::newton_direction(H_, 0.0, g_, d_);
      if (!have_step && model_ == Projection::kNone) {
        exact_none_ = false;
        model_ = Projection::kBoundaryJoints;
        reassemble(model_, tf);
        have_step = numerics::newton_direction(H_, 0.0, g_, d_);
      }
      if (!have_step) {
        // Not positive definite yet: back to the projected model for a while.
        exact_ = false;
        backoff_ = std::min(2 * backoff_ + 1, 8);
        projected_left_ = backoff_;
        model_ = Projection::kAll;
        reassemble(model_, tf);
      }
    }
    if (!have_step) {
      const numerics::ShiftResult shift = numerics::shifted_factorization(
          mu_, [&](double mu) { return numerics::newton_direction(H_, mu, g_, d_); });
      mu_ = shift.mu;
      if (!shift.ok) return false;
      if (mu_ > 0) ++rep_.shifted;
    }
    rep_.factor_seconds += seconds_since(tf);
    return true;
  }

  // The collision filter: the fraction of the full step along which every segment pair stays
  // above d_min (CCD). The line search starts at 0.9 of it (at the fraction itself the barrier
  // is infinite) and only shortens: no iterate ever has two segments pass through each other,
  // and the certificate records every accepted move. false: no step lowers the energy.
  bool step(double E) {
    const auto tl = SolveClock::now();
    const double slope = g_.dot(d_);
    const double bound = P_.step_bound(st_, d_);
    if (bound < 1.0) ++rep_.filtered;
    StripState trial;
    const numerics::LineSearchResult ls =
        numerics::armijo_backtracking(E, slope, bound < 1.0 ? 0.9 * bound : 1.0, [&](double a) {
          trial = st_;
          P_.apply_step(d_, a, trial);
          return P_.evaluate(trial);
        });
    alpha_ = ls.alpha;
    if (ls.accepted) {
      double Et = ls.energy;
      // A full step that gained about as much as its slope promised (a quadratic model gains
      // half) came from a model stiffer than the energy (the projection drops the negative
      // curvature of contact and bending): go further along it while the energy keeps
      // falling, within the filter's bound for the longer step. Measured on a 2 x 4 cm
      // stockinette strip: projected steps gained 0.97 of their slope, iteration after
      // iteration, at linear convergence.
      if (alpha_ == 1.0 && !exact_ && (Et - E) < 0.7 * slope) {
        StripState further;
        const numerics::Extension x = numerics::extend_step(
            alpha_, Et, slope, 8, 0.0,
            [&](double a) {
              if (P_.step_bound(st_, a * d_) < 1.0) return std::numeric_limits<double>::quiet_NaN();
              further = st_;
              P_.apply_step(d_, a, further);
              return P_.evaluate(further);
            },
            [&](double) { trial = std::move(further); });
        alpha_ = x.alpha;
        Et = x.energy;
      }
      st_ = std::move(trial);
      step_model_ = model_;
      add_move(st_.certificate, 1.0, std::numeric_limits<double>::infinity(), "Newton step");
      P_.track_frames(st_);
      if (opt_.verbose)
        std::fprintf(stderr, "           step %.3g (filter %.3g)  slope %.3e  dE %.3e\n", alpha_, bound, slope, Et - E);
    }
    rep_.line_search_seconds += seconds_since(tl);
    return ls.accepted;
  }

  // After an accepted step: a partial exact step goes back to projected steps; a full
  // projected one (after the back-off) tries the exact model next.
  void switch_model() {
    const bool full = alpha_ >= 1.0;
    if (exact_) {
      if (!full) exact_ = false;  // the quadratic model was not good: projected steps again
      else backoff_ = 0;
    } else if (full) {
      if (projected_left_ > 0) --projected_left_;
      else exact_ = true;
    }
  }

  Eigen::VectorXd d_;
  HessianFactor H_;
  bool exact_ = false, exact_none_ = true;
  int projected_left_ = 0, backoff_ = 0;
  double mu_ = 0.0, alpha_ = 0.0, previous_residual_ = std::numeric_limits<double>::infinity();
  Projection model_ = Projection::kAll;       // this iteration's model
  Projection step_model_ = Projection::kAll;  // the model of the last accepted step
};

}  // namespace

StripSolveReport solve_strip_switched(const StripProblem& P, StripState& st, const StripSolveOptions& opt) {
  return SwitchedNewton(P, st, opt).run();
}

}  // namespace yarnhom::yarn
