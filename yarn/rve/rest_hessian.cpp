#include "yarn/rve/rest_hessian.hpp"

#include <chrono>
#include <cmath>

#include "yarn/rve/energy_density.hpp"

namespace yarnhom::yarn {

RestHessian rest_hessian(const RveProblem& rve, const RveState& rest, const SolveOptions& opt, double h) {
  const auto t0 = std::chrono::steady_clock::now();
  RestHessian r;
  const Eigen::Matrix2d L = rve.lattice();
  const double len = std::max(L.col(0).norm(), L.col(1).norm());
  for (int i = 0; i < 6; ++i) r.step[i] = i < 3 ? h : h / len;
  SolveOptions so = opt;
  so.sensitivity_directions.clear();
  Eigen::Matrix<double, 6, 6> C;
  for (int i = 0; i < 6 && r.failure.empty(); ++i) {
    Strain g[2];
    for (int side = 0; side < 2; ++side) {
      Strain s = Strain::Zero();
      s[i] = side == 0 ? r.step[i] : -r.step[i];
      RveState st = rest;
      const DensityResult d = energy_density(rve, s, st, so);
      ++r.solves;
      if (!d.report.converged()) {
        r.failure = "the solve at s_" + std::to_string(i) + " = " + std::to_string(s[i]) + " did not converge (" +
                    d.report.summary() + ")";
        break;
      }
      g[side] = d.grad;
    }
    if (r.failure.empty()) C.col(i) = (g[0] - g[1]) / (2 * r.step[i]);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!r.failure.empty()) return r;
  r.H = 0.5 * (C + C.transpose());
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      if (i != j) {
        const double sc = std::sqrt(std::abs(C(i, i) * C(j, j)));
        if (sc > 0) r.asymmetry = std::max(r.asymmetry, std::abs(C(i, j) - C(j, i)) / sc);
      }
  r.ok = true;
  return r;
}

}  // namespace yarnhom::yarn
