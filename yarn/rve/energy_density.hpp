#pragma once
// The homogenized energy density of the RVE:  Psi(s) = E_min(s) / (px py)  (J/m^2), and its
// gradient by the envelope theorem: at an equilibrium the unknowns' variation does not change
// E to first order, so dPsi/ds = (1/(px py)) dE/ds at fixed unknowns (u, theta, frames). The
// zero-mode constraints do not depend on s, so the theorem applies to the constrained minimum.
#include "yarn/rve/newton.hpp"
#include "yarn/rve/rve.hpp"

namespace yarnhom::yarn {

struct DensityResult {
  double psi = 0;                   // J/m^2
  Strain grad = Strain::Zero();     // dPsi/ds (J/m^2 per unit strain, per 1/m for II)
  EnergyParts parts;                // J, at the solution
  SolveReport report;
};

// Solves at s from `state` (updated in place) and evaluates Psi and dPsi/ds. The result is
// returned whatever the status: check result.report.converged().
DensityResult energy_density(const RveProblem& rve, const Strain& s, RveState& state,
                             const SolveOptions& opt = {});

// Psi and dPsi/ds of a state as it is (no solve; dPsi/ds is the envelope gradient only if the
// state is an equilibrium).
DensityResult evaluate_density(const RveProblem& rve, const Strain& s, const RveState& state);

}  // namespace yarnhom::yarn
