#include "yarn/rve/energy_density.hpp"

namespace yarnhom::yarn {

DensityResult evaluate_density(const RveProblem& rve, const Strain& s, const RveState& state) {
  DensityResult r;
  Strain dE;
  Eigen::VectorXd g;
  const double E = rve.evaluate(s, state, &g, nullptr, &r.parts, &dE);
  r.psi = E / rve.area();
  r.grad = dE / rve.area();
  r.report.energy = E;
  r.report.residual = relative_residual(rve, g);
  return r;
}

DensityResult energy_density(const RveProblem& rve, const Strain& s, RveState& state,
                             const SolveOptions& opt) {
  const SolveReport rep = solve(rve, s, state, opt);
  DensityResult r = evaluate_density(rve, s, state);
  r.report = rep;
  return r;
}

}  // namespace yarnhom::yarn
