#include "yarn/strip_solve.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "yarn/hessian_factor.hpp"

namespace yarnhom::yarn {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

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
  if (g.size() == 0) return 0.0;
  return g.cwiseProduct(P.force_scale()).norm() / std::sqrt(double(g.size())) / P.stretch_stiffness();
}

StripSolveReport solve_strip(const StripProblem& P, StripState& st, const StripSolveOptions& opt) {
  return opt.method == StripSolveOptions::Method::kTrustRegion ? solve_strip_trust(P, st, opt)
                                                               : solve_strip_switched(P, st, opt);
}

StripSolveReport solve_strip_switched(const StripProblem& P, StripState& st, const StripSolveOptions& opt) {
  const auto t0 = Clock::now();
  StripSolveReport rep;
  const int N = P.num_dofs();
  Eigen::VectorXd g(N), d(N);
  BlockHessian B = P.make_hessian();
  HessianFactor H(N, opt.dense_limit);
  // Two models of the energy: `exact` (its Hessian) and projected (every element's Hessian
  // made positive semi-definite). Far from equilibrium the exact Hessian of a strip is
  // strongly indefinite (soft boundary yarn pressed by contact: measured scaled eigenvalues
  // down to -31), and a diagonal shift large enough to fix that makes every step tiny; the
  // projected model gives descent steps of the right size. Close to equilibrium the exact
  // Hessian is positive definite and converges quadratically: after each full projected step
  // the exact one is tried, and where it is not positive definite the solve goes back to
  // projected steps for 1, 2, 4, 8 iterations (as newton.cpp backs off plain Newton).
  // The exact model comes in two strengths: the exact Hessian itself (quadratic convergence),
  // and one whose boundary-yarn joints are projected (StripProblem::Projection): the soft
  // twist of those joints is often the only indefinite part near a solution (measured on a
  // stretched stockinette strip), but a model that drops curvature converges only linearly
  // (measured on a stocktiny wale strip: residual ratio 0.98 per iteration, 300 iterations at
  // 1e-9). So the exact Hessian is tried first; where it is not positive definite the partly
  // projected one is used, and the exact one is tried again as soon as steps of the partly
  // projected model stop reducing the residual fourfold per iteration.
  using Projection = StripProblem::Projection;
  bool exact = false, exact_none = true;
  int projected_left = 0, backoff = 0;
  double mu = 0.0, previous_residual = std::numeric_limits<double>::infinity();
  Projection step_model = Projection::kAll;  // the model of the last accepted step
  auto finish = [&](SolveStatus status) {
    rep.status = status;
    rep.seconds = since(t0);
    rep.analyses = H.analyses();
    return rep;
  };
  for (int it = 0;; ++it) {
    auto ta = Clock::now();
    Projection model = !exact ? Projection::kAll : exact_none ? Projection::kNone : Projection::kBoundaryJoints;
    const double E = P.evaluate(st, &g, &B, nullptr, nullptr, model);
    rep.energy = E;
    rep.residual = strip_residual(P, g);
    rep.iterations = it;
    if (!std::isfinite(E) || !std::isfinite(rep.residual)) return finish(SolveStatus::kNonFinite);
    // The partly projected model converging slowly: the exact one is tried at the next iteration.
    if (step_model == Projection::kBoundaryJoints && rep.residual > 0.25 * previous_residual) exact_none = true;
    previous_residual = rep.residual;
    if (opt.verbose)
      std::fprintf(stderr, "  newton %3d  E %.12g  residual %.3e  %s\n", it, E, rep.residual,
                   model == Projection::kAll ? "projected" : model == Projection::kNone ? "exact" : "exact (boundary joints projected)");
    if (rep.residual <= opt.tolerance) {
      rep.assembly_seconds += since(ta);
      st.certificate.min_distance = std::min(st.certificate.min_distance, P.min_distance(st) * 2 * P.radius());
      return finish(SolveStatus::kConverged);
    }
    if (it >= opt.max_iterations) return finish(SolveStatus::kMaxIterations);
    H.assemble(B.matrix());
    rep.assembly_seconds += since(ta);

    auto tf = Clock::now();
    bool have_step = false;
    auto exact_step = [&] {
      if (!H.factor(0.0)) return false;
      d = H.solve(-g);
      return d.allFinite() && g.dot(d) < 0;
    };
    auto reassemble = [&](Projection m) {
      rep.factor_seconds += since(tf);
      ta = Clock::now();
      P.evaluate(st, &g, &B, nullptr, nullptr, m);
      H.assemble(B.matrix());
      rep.assembly_seconds += since(ta);
      tf = Clock::now();
    };
    if (exact) {
      have_step = exact_step();
      if (!have_step && model == Projection::kNone) {
        exact_none = false;
        model = Projection::kBoundaryJoints;
        reassemble(model);
        have_step = exact_step();
      }
      if (!have_step) {
        // Not positive definite yet: back to the projected model for a while.
        exact = false;
        backoff = std::min(2 * backoff + 1, 8);
        projected_left = backoff;
        model = Projection::kAll;
        reassemble(model);
      }
    }
    if (!have_step) {
      // Projected model (positive semi-definite): shift only where it is singular, or where a
      // line search failed (mu raised below).
      for (int tries = 0;; ++tries) {
        bool ok = H.factor(mu);
        if (ok) {
          d = H.solve(-g);
          ok = d.allFinite() && g.dot(d) < 0;
        }
        if (ok) break;
        if (tries > 40) return finish(SolveStatus::kNonFinite);
        mu = mu == 0 ? 1e-8 : mu * 10;
      }
      if (mu > 0) ++rep.shifted;
    }
    rep.factor_seconds += since(tf);

    // The collision filter: the fraction of the full step along which every segment pair
    // stays above d_min (CCD). The line search starts at 0.9 of it (at the fraction itself the
    // barrier is infinite) and only shortens: no iterate ever has two segments pass through
    // each other, and the certificate records every accepted move.
    auto tl = Clock::now();
    const double slope = g.dot(d);
    const double bound = P.step_bound(st, d);
    if (bound < 1.0) ++rep.filtered;
    double alpha = bound < 1.0 ? 0.9 * bound : 1.0;
    bool accepted = false;
    for (int ls = 0; ls < 40; ++ls) {
      StripState trial = st;
      P.apply_step(d, alpha, trial);
      double Et = P.evaluate(trial);
      if (std::isfinite(Et) && (Et <= E + 1e-4 * alpha * slope || -slope < 1e-13 * std::abs(E))) {
        // A full step that gained about as much as its slope promised (a quadratic model gains
        // half) came from a model stiffer than the energy (the projection drops the negative
        // curvature of contact and bending): go further along it while the energy keeps
        // falling, within the filter's bound for the longer step. Measured on a 2 x 4 cm
        // stockinette strip: projected steps gained 0.97 of their slope, iteration after
        // iteration, at linear convergence.
        if (alpha == 1.0 && !exact && (Et - E) < 0.7 * slope) {
          for (int ex = 0; ex < 8; ++ex) {
            if (P.step_bound(st, 2 * alpha * d) < 1.0) break;
            StripState further = st;
            P.apply_step(d, 2 * alpha, further);
            const double Ef = P.evaluate(further);
            if (!(std::isfinite(Ef) && Ef < Et)) break;
            alpha *= 2;
            trial = std::move(further);
            Et = Ef;
          }
        }
        st = std::move(trial);
        step_model = model;
        add_move(st.certificate, 1.0, std::numeric_limits<double>::infinity(), "Newton step");
        P.track_frames(st);
        accepted = true;
        if (opt.verbose)
          std::fprintf(stderr, "           step %.3g (filter %.3g)  slope %.3e  dE %.3e\n", alpha, bound, slope, Et - E);
        break;
      }
      alpha *= 0.5;
    }
    rep.line_search_seconds += since(tl);
    if (!accepted) {
      if (++rep.line_search_retries > 8) return finish(SolveStatus::kLineSearchFailed);
      mu = std::max(mu * 100, 1e-3);
      exact = false;
      continue;
    }
    mu = mu < 1e-7 ? 0.0 : mu / 10;
    const bool full = alpha >= 1.0;
    if (exact) {
      if (!full) exact = false;  // the quadratic model was not good: projected steps again
      else backoff = 0;
    } else if (full) {
      if (projected_left > 0) --projected_left;
      else exact = true;
    }
  }
}

}  // namespace yarnhom::yarn
