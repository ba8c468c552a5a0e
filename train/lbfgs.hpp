#pragma once
// Limited-memory BFGS (Nocedal & Wright, Numerical Optimization, 2nd ed., Alg. 7.4 and 7.5)
// with a strong-Wolfe line search (Alg. 3.5 and 3.6, cubic interpolation in the zoom), for
// the full-batch polish of a network (train/polish.hpp). The state is in double; the objective
// may compute in float.
//
// Why hand-written: the polish is part of the training engine, like Adam, and needs what a
// packaged solver does not give: the objective is evaluated through our own fused kernels,
// the caller watches every accepted iterate (to keep the one with the best validation loss),
// and a line search that cannot make progress (float rounding near a minimum) must end the
// run quietly rather than throw.
//
//   direction  p = -H g, H the inverse-Hessian approximation from the last m pairs
//              (s, y) = (x_{k+1} - x_k, g_{k+1} - g_k), applied by the two-loop recursion
//              with the initial scaling gamma = s.y / y.y;
//   step       a with f(x + a p) <= f + c1 a g.p and |g(x + a p).p| <= c2 |g.p|
//              (c1 = 1e-4, c2 = 0.9), the first trial a = 1 (after the first iteration,
//              where a = min(1, 1/|g|_1)).
// A pair with s.y <= 1e-12 |s| |y| is skipped (the curvature condition failed in rounding).
#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace yarnhom {

// The stop reason of a line search that found no lower point (PolishResult::stop).
inline constexpr const char* kLbfgsNoProgress = "line search made no progress";

struct LbfgsOptions {
  int max_iterations = 500;
  int memory = 10;
  double c1 = 1e-4, c2 = 0.9;
  int max_evaluations_per_search = 25;
  double rel_tolerance = 1e-12;  // stop when a step lowers f by less than this fraction of |f|
};

struct LbfgsResult {
  int iterations = 0, evaluations = 0;
  double f0 = 0, f = 0;
  std::string stop;  // why it ended
};

// fg(x, g) returns f(x) and writes its gradient into g. on_iterate(k, x, f) is called after
// every accepted step (k = 1, 2, ...); returning false stops the run.
using LbfgsObjective = std::function<double(const Eigen::VectorXd& x, Eigen::VectorXd& g)>;
using LbfgsObserver = std::function<bool(int k, const Eigen::VectorXd& x, double f)>;

// The two-loop recursion: p = -H g, H the inverse-Hessian estimate of the pairs (S, Y) with
// rho = 1 / (s . y), scaled by the newest pair's s . y / |y|^2. alpha: scratch of the memory's size.
inline void lbfgs_direction(const Eigen::VectorXd& g, const std::deque<Eigen::VectorXd>& S,
                            const std::deque<Eigen::VectorXd>& Y, const std::deque<double>& rho,
                            std::vector<double>& alpha, Eigen::VectorXd& p) {
  p = -g;
  const int m = int(S.size());
  for (int i = m - 1; i >= 0; --i) {
    alpha[i] = rho[i] * S[i].dot(p);
    p -= alpha[i] * Y[i];
  }
  if (m > 0) p *= S.back().dot(Y.back()) / Y.back().squaredNorm();
  for (int i = 0; i < m; ++i) {
    const double beta = rho[i] * Y[i].dot(p);
    p += (alpha[i] - beta) * S[i];
  }
}

// The zoom's trial step: the minimizer of the cubic through both ends of the bracket (values
// and slopes), the midpoint where that fails, safeguarded into the bracket's middle 80 %.
inline double cubic_step(double a_lo, double f_lo, double d_lo, double a_hi, double f_hi, double d_hi) {
  const double lo = std::min(a_lo, a_hi), hi = std::max(a_lo, a_hi), w = hi - lo;
  double trial = 0.5 * (a_lo + a_hi);
  if (std::isfinite(f_hi) && std::isfinite(d_hi)) {
    const double d1 = d_lo + d_hi - 3 * (f_lo - f_hi) / (a_lo - a_hi);
    const double disc = d1 * d1 - d_lo * d_hi;
    if (disc >= 0) {
      const double d2 = std::copysign(std::sqrt(disc), a_hi - a_lo);
      const double c = a_hi - (a_hi - a_lo) * (d_hi + d2 - d1) / (d_hi - d_lo + 2 * d2);
      if (std::isfinite(c)) trial = c;
    }
  }
  return std::clamp(trial, lo + 0.1 * w, hi - 0.1 * w);
}

inline LbfgsResult lbfgs_minimize(Eigen::VectorXd& x, const LbfgsObjective& fg, const LbfgsOptions& opt,
                                  const LbfgsObserver& on_iterate = {}) {
  using Vec = Eigen::VectorXd;
  LbfgsResult res;
  const Eigen::Index n = x.size();
  Vec g(n), p(n), xt(n), gt(n);
  double f = fg(x, g);
  ++res.evaluations;
  res.f0 = res.f = f;
  if (!std::isfinite(f) || !g.allFinite()) {
    res.stop = "non-finite objective at the start";
    return res;
  }
  std::deque<Vec> S, Y;
  std::deque<double> rho;
  std::vector<double> alpha(opt.memory);

  for (int k = 0; k < opt.max_iterations; ++k) {
    lbfgs_direction(g, S, Y, rho, alpha, p);  // p = -H g
    double dg0 = g.dot(p);
    if (!(dg0 < 0)) {  // not a descent direction (rounding): restart from steepest descent
      S.clear();
      Y.clear();
      rho.clear();
      p = -g;
      dg0 = -g.squaredNorm();
      if (!(dg0 < 0)) {
        res.stop = "zero gradient";
        break;
      }
    }
    double a = (k == 0 && S.empty()) ? std::min(1.0, 1.0 / g.lpNorm<1>()) : 1.0;

    // Strong-Wolfe line search: bracket, then zoom.
    auto eval = [&](double step, double& fv, double& dv) {
      xt = x + step * p;
      fv = fg(xt, gt);
      ++res.evaluations;
      dv = gt.dot(p);
      return std::isfinite(fv) && std::isfinite(dv);
    };
    double a_prev = 0, f_prev = f, d_prev = dg0;
    double a_lo = 0, f_lo = f, d_lo = dg0, a_hi = 0, f_hi = 0, d_hi = 0;
    bool found = false, zoom = false;
    int evals = 0;
    double fa = 0, da = 0;
    while (evals < opt.max_evaluations_per_search) {
      ++evals;
      const bool finite = eval(a, fa, da);
      if (!finite || fa > f + opt.c1 * a * dg0 || (evals > 1 && fa >= f_prev)) {
        if (!finite) {  // overflow: treat as too long a step
          fa = INFINITY;
          da = INFINITY;
        }
        a_lo = a_prev; f_lo = f_prev; d_lo = d_prev;
        a_hi = a; f_hi = fa; d_hi = da;
        zoom = true;
        break;
      }
      if (std::abs(da) <= -opt.c2 * dg0) {
        found = true;
        break;
      }
      if (da >= 0) {
        a_lo = a; f_lo = fa; d_lo = da;
        a_hi = a_prev; f_hi = f_prev; d_hi = d_prev;
        zoom = true;
        break;
      }
      a_prev = a; f_prev = fa; d_prev = da;
      a *= 2;
    }
    while (zoom && !found && evals < opt.max_evaluations_per_search) {
      ++evals;
      // Cubic interpolation between the bracket's ends, safeguarded into its middle 80%.
      const double lo = std::min(a_lo, a_hi), hi = std::max(a_lo, a_hi), w = hi - lo;
      a = cubic_step(a_lo, f_lo, d_lo, a_hi, f_hi, d_hi);
      const bool finite = eval(a, fa, da);
      if (!finite || fa > f + opt.c1 * a * dg0 || fa >= f_lo) {
        a_hi = a; f_hi = finite ? fa : INFINITY; d_hi = finite ? da : INFINITY;
      } else {
        if (std::abs(da) <= -opt.c2 * dg0) {
          found = true;
          break;
        }
        if (da * (a_hi - a_lo) >= 0) {
          a_hi = a_lo; f_hi = f_lo; d_hi = d_lo;
        }
        a_lo = a; f_lo = fa; d_lo = da;
      }
      if (w < 1e-14 * std::max(1.0, hi)) break;
    }
    if (!found) {
      // No Wolfe point: accept the best sufficient-decrease point seen, if any.
      if (a_lo > 0 && f_lo < f) {
        a = a_lo;
        eval(a, fa, da);
      } else {
        res.stop = kLbfgsNoProgress;
        break;
      }
    }
    // Accept: update the history with (s, y) (the oldest pair's vectors reused: no allocation).
    const double sy = (xt - x).dot(gt - g);
    if (sy > 1e-12 * (xt - x).norm() * (gt - g).norm()) {
      Vec s, y;
      if (int(S.size()) == opt.memory) {
        s = std::move(S.front());
        y = std::move(Y.front());
        S.pop_front();
        Y.pop_front();
        rho.pop_front();
      }
      s = xt - x;
      y = gt - g;
      S.push_back(std::move(s));
      Y.push_back(std::move(y));
      rho.push_back(1.0 / sy);
    }
    const double f_old = f;
    x.swap(xt);
    g.swap(gt);
    f = fa;
    res.f = f;
    res.iterations = k + 1;
    if (on_iterate && !on_iterate(k + 1, x, f)) {
      res.stop = "stopped by the observer";
      break;
    }
    if (f_old - f <= opt.rel_tolerance * std::abs(f)) {
      res.stop = "converged (relative decrease below tolerance)";
      break;
    }
  }
  if (res.stop.empty()) res.stop = "iteration limit";
  return res;
}

}  // namespace yarnhom
