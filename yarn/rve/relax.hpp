#pragma once
// Relaxing a pattern at rest (s = 0) and writing the equilibrium back as a pattern: positions,
// twist angles and reference frames of the solution; rest lengths, curvatures and twists
// unchanged (they are the material's). Loading the result gives an RVE whose initial state is
// already an equilibrium.
#include "yarn/rve/newton.hpp"
#include "yarn/rod/pattern.hpp"

namespace yarnhom::yarn {

// The pattern whose stored geometry is `state` at strain s = 0.
Pattern pattern_at(const RveProblem& rve, const RveState& state);

// Solves at s = 0 from the pattern's own state; throws std::runtime_error naming the pattern
// if the solve does not converge.
Pattern relax_pattern(const Pattern& p, const Material& m, SolveReport* report = nullptr,
                      const SolveOptions& opt = {});

}  // namespace yarnhom::yarn
