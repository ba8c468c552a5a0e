#include "sim/newton.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace yarnhom::sim {

namespace {
using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }
}  // namespace

NewtonStats newton_minimize(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                            const StepState& S, Eigen::VectorXd& x, const NewtonSettings& opt, bool profile) {
  NewtonStats st;
  Eigen::SparseMatrix<double> H = pat.matrix;
  Eigen::VectorXd grad(x.size());
  const int F = D.num_free();
  if (F == 0) {
    st.converged = true;
    st.energy = potential_value(P, D, S, x);
    return st;
  }
  for (int it = 0; it < opt.max_iterations; ++it) {
    auto t0 = Clock::now();
    std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
    const double E = potential_derivatives(P, D, pat, S, x, grad, H.valuePtr(), profile ? &st.shell : nullptr);
    st.energy = E;
    const Eigen::VectorXd g = gather_free(D, grad);
    auto t1 = Clock::now();
    st.t_assemble += seconds(t0, t1);
    // Factorize; on failure shift the diagonal by a growing multiple of its mean magnitude.
    double mean_diag = 0;
    for (int k = 0; k < 3 * F; ++k) mean_diag += H.valuePtr()[pat.diag_slots[k]];
    mean_diag = std::max(std::abs(mean_diag) / (3 * F), 1e-300);
    double shift = 0;
    bool ok = solver.factorize(H);
    for (int tries = 0; !ok && tries < 12; ++tries) {
      const double add = (shift == 0 ? 1e-8 : 9 * shift) * mean_diag;
      shift = shift == 0 ? 1e-8 : 10 * shift;
      for (int k = 0; k < 3 * F; ++k) H.valuePtr()[pat.diag_slots[k]] += add;
      ok = solver.factorize(H);
    }
    if (shift > 0) ++st.shifted;
    if (!ok) break;
    const Eigen::VectorXd pf = -solver.solve(g);
    auto t2 = Clock::now();
    st.t_solve += seconds(t1, t2);
    ++st.iterations;
    st.step_norm = pf.cwiseAbs().maxCoeff();
    if (!std::isfinite(st.step_norm)) break;
    if (st.step_norm < opt.tol_step) {
      st.converged = true;
      break;
    }
    Eigen::VectorXd p = Eigen::VectorXd::Zero(x.size());
    scatter_free(D, pf, p);
    double alpha = max_feasible_step(P, x, p);
    const double slope = g.dot(pf);  // < 0 for a positive-definite solve
    Eigen::VectorXd xn;
    double En = 0;
    bool accepted = false;
    for (int ls = 0; ls < 40; ++ls) {
      xn = x + alpha * p;
      En = potential_value(P, D, S, xn);
      if (std::isfinite(En) && En <= E + opt.armijo * alpha * slope) {
        accepted = true;
        break;
      }
      alpha *= 0.5;
      ++st.backtracks;
    }
    // A full step that decreased the energy more than its quadratic model predicts (En - E <
    // slope/2 for a Newton step) crossed a region of negative curvature, which the projected
    // Hessian flattened to zero: the step is too short there. Extend it while the energy keeps
    // falling (up to 16 steps, within the collider bound), instead of creeping.
    if (accepted && alpha == 1.0 && En - E < 0.5 * slope) {
      const double amax = 16 * max_feasible_step(P, x, 16 * p);  // multiple of p allowed from x
      double a = 1.0;
      while (2 * a <= std::min(16.0, amax)) {
        const Eigen::VectorXd xt = x + (2 * a) * p;
        const double Et = potential_value(P, D, S, xt);
        if (!(std::isfinite(Et) && Et < En)) break;
        a *= 2;
        xn = xt;
        En = Et;
        ++st.extensions;
      }
    }
    st.t_line_search += seconds(t2, Clock::now());
    if (!accepted) {
      // No decrease at rounding level: the step is below what the energy resolves.
      st.converged = alpha * st.step_norm < opt.tol_step || std::abs(slope) < 1e-14 * (1 + std::abs(E));
      break;
    }
    if (std::getenv("YARNHOM_SIM_DEBUG"))
      std::fprintf(stderr, "  newton %d: E %.12g -> %.12g, |p| %.3g, alpha %.3g, slope %.3g, shift %g\n", it, E, En,
                   st.step_norm, alpha, slope, shift);
    x = xn;
    st.energy = En;
  }
  return st;
}

}  // namespace yarnhom::sim
