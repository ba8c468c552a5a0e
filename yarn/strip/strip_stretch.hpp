#pragma once
// The clamped quasi-static stretch test of a yarn strip (supplement section 4.2; docs/strip.md
// says exactly what is measured).
//
// Clamps: every vertex whose coordinate along the long axis lies within `band` of either end
// of the nominal strip (or beyond it: the selvedge connectors of a course test) is held by the
// clamp of that end, a rigid body that only translates along the axis; edges with both ends
// held keep their twist. Stretch lambda: the clamps are translated by -/+ (lambda - 1) L / 2
// from where the strip was generated (L its nominal length), so the nominal length becomes
// lambda L. lambda = 1 is the generated strip relaxed with the clamps in place.
//
// Force: with E the strip's energy and x_v its vertices, the force clamp c applies to the
// strip along the axis a is F_c = sum over its vertices of dE/dx_v . a (at equilibrium the
// clamp balances the yarn's internal force on every vertex it holds). The two balance,
// F_low + F_high = 0, up to the solver's residual. The force reported is
// F = (F_high - F_low) / 2, which by the envelope theorem is dE_min/d(separation) exactly,
// and the tension is F / W in N/m, W the strip's nominal (undeformed) width.
#include <functional>
#include <vector>

#include "yarn/strip/strip_solve.hpp"

namespace yarnhom::yarn {

// Clamp flags (-1 low end, +1 high end, 0 free) from the strip's generated geometry.
std::vector<signed char> clamp_flags(const Strip& s, double band);

struct StretchStep {
  double stretch = 1;
  double force_low = 0, force_high = 0;  // N, along the axis (what each clamp applies)
  double force = 0;                      // N: (force_high - force_low) / 2
  double tension = 0;                    // N/m: force / nominal width
  double energy = 0;                     // J
  EnergyParts parts;
  double min_distance = 0;               // closest segment pair at the equilibrium / 2r
  ContactCertificate certificate;        // every move since the generated strip (state's)
  StripSolveReport solve;
};

class StripStretch {
 public:
  // axis: unit vector along which the clamps move (the strip's long axis, turned with it when
  // the whole strip is moved rigidly); reference: the vertex positions at lambda = 1.
  StripStretch(const StripProblem& P, Eigen::Vector3d axis, std::vector<Eigen::Vector3d> reference);

  const StripProblem& problem() const { return P_; }
  const Eigen::Vector3d& axis() const { return axis_; }
  // Puts the clamped vertices where the clamps hold them at `stretch`.
  void place_clamps(StripState& st, double stretch) const;
  // Predictor from an equilibrium at stretch `from` to `to`: every vertex moved along the axis
  // by a displacement that is -D in the low clamp, +D in the high one and linear in the axis
  // coordinate between them (D = (to - from) L / 2). It never decreases any distance between
  // two points when to > from, so it cannot make yarns cross.
  void predict(StripState& st, double from, double to) const;
  // Clamp reactions and the derived figures of an equilibrium (no solve).
  StretchStep measure(const StripState& st, double stretch) const;
  // Predict from `from` (skipped when to == from), solve, re-base the frames on success.
  StretchStep step(StripState& st, double from, double to, const StripSolveOptions& opt) const;

 private:
  const StripProblem& P_;
  Eigen::Vector3d axis_;
  std::vector<Eigen::Vector3d> ref_;
};

}  // namespace yarnhom::yarn
