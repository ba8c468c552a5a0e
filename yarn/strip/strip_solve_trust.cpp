// A trust-region Newton method for a strip's equilibrium: Steihaug-Toint conjugate gradients
// on the EXACT Hessian, preconditioned by the Cholesky factor of the PROJECTED Hessian
// (docs/strip.md section 4).
//
// Why: near a stretched strip's equilibrium the exact Hessian is indefinite along a few soft
// directions (boundary yarn at 1/200 of the moduli pressed by full-strength loops, free
// edges). Projected Newton steps drop exactly that negative curvature and creep (measured on
// the paper's stockinette: phases of 100-200 iterations at a residual near 3e-5); a
// Levenberg-Marquardt shift on the exact Hessian needs one failed Cholesky per attempt to find
// its size, and the shift then limits every step. Here each iteration factors one matrix that
// is always positive (semi-)definite, the projected Hessian M (every element's Hessian
// projected onto the PSD cone), and minimizes the exact quadratic model
//
//     m(s) = g.s + s.H s / 2      subject to  |s|_M = sqrt(s.M s) <= Delta
//
// by preconditioned CG (Steihaug 1983, Toint 1981): CG iterates grow monotonically in the M
// norm; CG stops at the trust-region boundary when an iterate would leave it or when a search
// direction has non-positive curvature (then the step follows that direction to the boundary:
// the negative curvature is used, not dropped), or inside when the model's residual has fallen
// by the forcing factor eta. Where M is close to H (a convex neighbourhood) CG converges in a
// few iterations and the step is Newton's. Each iteration costs one assembly (both Hessians in
// one pass), one factorization and a few sparse products and triangular solves.
//
// When it stalls (the radius below 1e-6 of the first, or the residual not halved for
// `trust_stall_iterations`), the switched method finishes the solve from where it is.
//
// Delta follows the ratio rho of the actual to the predicted decrease: below 0.25 it shrinks
// to a quarter of the step, above 0.75 with a step on the boundary it doubles. A step is taken
// when it decreases the energy (Armijo on the model's decrease). The collision filter
// shortens each step to 0.9 of the fraction CCD finds safe, exactly as the other methods.
#include <algorithm>
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

namespace {

struct SteihaugResult {
  Eigen::VectorXd s;
  int iterations = 0;
  bool boundary = false;  // stopped on the trust-region boundary
  bool negative = false;  // because of non-positive curvature
};

// Minimizes g.s + s.H s / 2 over |s|_M <= delta by preconditioned CG from s = 0. H: lower
// triangle; M^-1 through the factorization. Stops inside when the preconditioned residual
// falls below eta times its start.
SteihaugResult steihaug(const Eigen::SparseMatrix<double>& H_lower, const HessianFactor& M, const Eigen::VectorXd& g,
                        double delta, double eta, int max_iterations) {
  const auto H = H_lower.selfadjointView<Eigen::Lower>();
  SteihaugResult out;
  const int n = static_cast<int>(g.size());
  out.s.setZero(n);
  Eigen::VectorXd r = g;               // model gradient at s: g + H s
  Eigen::VectorXd z = M.solve(r);      // preconditioned
  Eigen::VectorXd p = -z;
  double rz = r.dot(z);
  const double stop = eta * std::sqrt(std::max(rz, 0.0));
  // M norms, updated by recurrence: |s|^2, s.M p, |p|^2.
  double ss = 0, sp = 0, pp = rz;
  // tau >= 0 with |s + tau p|_M = delta.
  auto to_boundary = [&]() {
    const double disc = std::max(sp * sp + pp * (delta * delta - ss), 0.0);
    return (-sp + std::sqrt(disc)) / pp;
  };
  Eigen::VectorXd Hp(n);
  for (int j = 0; j < max_iterations; ++j) {
    out.iterations = j + 1;
    if (!(rz > 0) || !(pp > 0)) break;
    Hp.noalias() = H * p;
    const double kappa = p.dot(Hp);
    if (kappa <= 0) {
      out.s += to_boundary() * p;
      out.boundary = out.negative = true;
      return out;
    }
    const double alpha = rz / kappa;
    const double ss_next = ss + 2 * alpha * sp + alpha * alpha * pp;
    if (ss_next >= delta * delta) {
      out.s += to_boundary() * p;
      out.boundary = true;
      return out;
    }
    out.s += alpha * p;
    r += alpha * Hp;
    z = M.solve(r);
    const double rz_next = r.dot(z);
    ss = ss_next;
    if (std::sqrt(std::max(rz_next, 0.0)) <= stop) break;
    const double beta = rz_next / rz;
    sp = beta * (sp + alpha * pp);
    pp = rz_next + beta * beta * pp;
    p = -z + beta * p;
    rz = rz_next;
  }
  return out;
}

// One trial: the Steihaug step for a radius, filtered, and its energy.
struct Trial {
  bool ok = false;  // decreases the energy enough (Armijo on the model's decrease)
  bool boundary = false;
  double rho = -1, Et = 0, norm = 0;
  StripState state;
};

class TrustRegionNewton : StripNewton {
 public:
  TrustRegionNewton(const StripProblem& P, StripState& st, const StripSolveOptions& opt)
      : StripNewton(P, st, opt), Bp_(P.make_hessian()), M_(P.num_dofs(), opt.dense_limit) {}

  StripSolveReport run() {
    // Radius: in the preconditioner's norm, started at the first projected Newton step's
    // length and carried from iteration to iteration.
    for (int it = 0;; ++it) {
      auto ta = SolveClock::now();
      E_ = P_.evaluate(st_, &g_, &B_, nullptr, nullptr, StripProblem::Projection::kNone, &Bp_);
      it_ = it;
      if (!record(it, E_)) return finish(SolveStatus::kNonFinite);
      if (rep_.residual <= opt_.tolerance) {
        converged(ta);
        return finish(SolveStatus::kConverged);
      }
      if (it >= opt_.max_iterations) return finish(SolveStatus::kMaxIterations);
      if (stalled()) return switched_rest();
      M_.assemble(Bp_.matrix());
      rep_.assembly_seconds += seconds_since(ta);

      auto tf = SolveClock::now();
      const numerics::ShiftResult shift = numerics::shifted_factorization(mu_, [&](double mu) { return M_.factor(mu); });
      mu_ = shift.mu;
      if (!shift.ok) return finish(SolveStatus::kNonFinite);
      if (mu_ > 0) ++rep_.shifted;
      rep_.factor_seconds += seconds_since(tf);
      const auto tl = SolveClock::now();
      const bool accepted = trust_step();
      rep_.line_search_seconds += seconds_since(tl);
      mu_ = numerics::relaxed_shift(mu_);
      if (!accepted) {
        if (++rejected_in_a_row_ > 3) return finish(SolveStatus::kLineSearchFailed);
        ++rep_.line_search_retries;
      } else {
        rejected_in_a_row_ = 0;
      }
    }
  }

 private:
  StripSolveReport finish(SolveStatus status) {
    if (opt_.verbose) std::fprintf(stderr, "  trust region: %d CG iterations in all\n", cg_total_);
    return StripNewton::finish(status, M_.analyses());
  }

  // Stalled: the radius collapsed, or the residual has not halved for a long while. Measured
  // on the paper's stockinette at 140 %: the exact model was good only within radii 1e-6 to
  // 1e-8 of the first one, the residual bounced between 1e-2 and 1e3 for 250 iterations; the
  // switched method converged from the same start in 127. The rest of the solve is left to it.
  // (In every other load step measured the radius stayed above 2e-5 of the first and the
  // residual halved at least every 100 iterations.)
  bool stalled() {
    if (rep_.residual < 0.5 * best_residual_) {
      best_residual_ = rep_.residual;
      best_at_ = it_;
    }
    return it_ - best_at_ >= opt_.trust_stall_iterations || (delta_ > 0 && delta_ < 1e-6 * first_delta_);
  }

  // The switched method finishes the solve from where it is, within the iterations left.
  StripSolveReport switched_rest() {
    if (opt_.verbose)
      std::fprintf(stderr, "  trust region stalled after %d iterations (residual %.3e, radius %.2e of the first): switched method\n",
                   it_, rep_.residual, delta_ / first_delta_);
    StripSolveOptions rest = opt_;
    rest.max_iterations = opt_.max_iterations - it_;
    const StripSolveReport sw = solve_strip_switched(P_, st_, rest);
    rep_.status = sw.status;
    rep_.iterations = it_ + sw.iterations;
    rep_.residual = sw.residual;
    rep_.energy = sw.energy;
    rep_.assembly_seconds += sw.assembly_seconds;
    rep_.factor_seconds += sw.factor_seconds;
    rep_.line_search_seconds += sw.line_search_seconds;
    rep_.shifted += sw.shifted;
    rep_.filtered += sw.filtered;
    rep_.line_search_retries += sw.line_search_retries;
    rep_.fallback = true;
    rep_.seconds = seconds_since(t0_);
    rep_.analyses = M_.analyses() + sw.analyses;
    return rep_;
  }

  // The Steihaug step for `radius`, filtered, and its energy.
  Trial attempt(double radius, double eta) {
    Trial tr;
    const SteihaugResult cg = steihaug(B_.matrix(), M_, g_, radius, eta, 200);
    cg_total_ += cg.iterations;
    const Eigen::VectorXd& s = cg.s;
    const double gs = g_.dot(s);
    const double sHs = s.dot(B_.matrix().selfadjointView<Eigen::Lower>() * s);
    const double sMs = s.dot(Bp_.matrix().selfadjointView<Eigen::Lower>() * s);
    const double bound = gs < 0 ? P_.step_bound(st_, s) : 0.0;
    const double t = bound < 1.0 ? 0.9 * bound : 1.0;
    const double predicted = t * gs + 0.5 * t * t * sHs;  // the model's change (negative)
    tr.boundary = cg.boundary && t == 1.0;
    tr.norm = t * std::sqrt(std::max(sMs, 0.0));
    if (predicted < 0) {
      tr.state = st_;
      P_.apply_step(s, t, tr.state);
      tr.Et = P_.evaluate(tr.state);
      tr.rho = std::isfinite(tr.Et) ? (tr.Et - E_) / predicted : -1;
      tr.ok = std::isfinite(tr.Et) && (tr.Et - E_ <= 1e-4 * predicted || -predicted < 1e-13 * std::abs(E_));
    }
    if (opt_.verbose)
      std::fprintf(stderr, "  newton %3d  E %.12g  residual %.3e  delta %.2e |s|_M %.2e cg %d%s%s filter %.3g rho %.3f %s\n",
                   it_, E_, rep_.residual, radius, tr.norm, cg.iterations, cg.boundary ? " boundary" : "",
                   cg.negative ? " negative" : "", bound, tr.rho, tr.ok ? "ok" : "rejected");
    return tr;
  }

  // Shrink the region until a step decreases the energy; then, while the model stays good and
  // the step is on the boundary, try twice the radius with the same factorization (a trial
  // costs a few CG iterations and one energy, an iteration an assembly and a factorization:
  // measured on a stockinette strip, the model is good to a radius that varies by orders of
  // magnitude as contacts open and close). true: a step was taken.
  bool trust_step() {
    // Forcing term: loose far from the solution, tight near it (superlinear convergence).
    const double eta = std::clamp(std::sqrt(rep_.residual), 1e-6, 0.1);
    if (delta_ < 0) {
      const Eigen::VectorXd z = M_.solve(g_);
      first_delta_ = delta_ = std::sqrt(std::max(g_.dot(z), 0.0));  // the projected Newton step's M norm
    }
    Trial best;
    for (int k = 0; k < 30; ++k) {
      best = attempt(delta_, eta);
      if (best.ok) break;
      delta_ = 0.5 * std::min(delta_, std::max(best.norm, 1e-12 * delta_));
    }
    if (!best.ok) return false;
    bool larger_failed = false;
    while (best.rho > 0.75 && best.boundary) {
      Trial further = attempt(2 * delta_, eta);
      if (!(further.ok && further.Et < best.Et && further.rho > 0.25)) {
        larger_failed = true;
        break;
      }
      delta_ *= 2;
      best = std::move(further);
    }
    if (best.rho < 0.25) delta_ = 0.5 * best.norm;
    else if (best.rho > 0.75 && best.boundary && !larger_failed) delta_ *= 2;
    st_ = std::move(best.state);
    add_move(st_.certificate, 1.0, std::numeric_limits<double>::infinity(), "Newton step");
    P_.track_frames(st_);
    return true;
  }

  BlockHessian Bp_;  // the projected Hessian, assembled with the exact one (B_)
  HessianFactor M_;
  double E_ = 0;
  int it_ = 0;
  double delta_ = -1;  // trust radius in the M norm; set from the first preconditioned step
  double first_delta_ = -1;
  double best_residual_ = std::numeric_limits<double>::infinity();
  int best_at_ = 0;
  double mu_ = 0;  // shift of M, only where the projected Hessian is singular
  int cg_total_ = 0;
  int rejected_in_a_row_ = 0;
};

}  // namespace

StripSolveReport solve_strip_trust(const StripProblem& P, StripState& st, const StripSolveOptions& opt) {
  return TrustRegionNewton(P, st, opt).run();
}

}  // namespace yarnhom::yarn
