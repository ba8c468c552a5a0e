#pragma once
// Outward rays of the TOTAL baked energy, for the safeguard tests (docs/bake.md, "The
// safeguard outside the box"). An outward ray starts at a point of the box boundary and goes in
// a direction of the normal cone there: along the outward normal from a face point, any
// direction of the outward quadrant (orthant) from a point where several coordinates sit on
// the boundary. Every point outside the box lies on exactly one such ray, so they sweep every
// sector. Along a ray the test records the energy F(t) and its slope S(t) = dF/dt and counts
//   - rays whose slope decreases (the continuation bent the total down), and
//   - rays that start with S(0) >= 0 and later have S < 0 (the total turned back).
// A ray that starts falling (S(0) < 0: the data fall outward in total) is allowed to keep a
// negative slope, but not to fall faster.
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "material/baked_eval.hpp"
#include "bake/pair_check.hpp"

namespace yarnhom::test {

struct RayTally {
  int rays = 0, corner_rays = 0;  // rays walked; of which from a corner / several bounds
  int skipped = 0;                // corner rays of a corner the pair check reports as bending down
  int slope_falls = 0;            // the slope decreased somewhere
  int turns_back = 0;             // S(0) >= 0 but S < 0 later
  int start_falling = 0;          // S(0) < 0 (reported data, allowed)
};

// F and dF/dt at p + t v; `scale` is the slope scale for rounding tolerances.
using RayEnergy = std::function<void(const std::vector<double>& x, const std::vector<double>& v, double& F, double& S)>;

// Walks one ray of `steps` steps from p along v to parameter tmax and adds it to the tally.
inline void walk_ray(const RayEnergy& E, const std::vector<double>& p, const std::vector<double>& v, double tmax,
                     double slope_scale, RayTally& tally, int steps = 200) {
  std::vector<double> x(p.size());
  double S0 = 0, Sp = -1e300;
  bool falls = false, back = false;
  for (int k = 0; k <= steps; ++k) {
    const double t = tmax * k / steps;
    for (size_t i = 0; i < p.size(); ++i) x[i] = p[i] + t * v[i];
    double F, S;
    E(x, v, F, S);
    const double tol = 1e-9 * std::abs(S) + 1e-9 * slope_scale;
    if (k == 0) S0 = S;
    if (k > 0 && S < Sp - tol) falls = true;
    if (S0 >= -tol && S < -tol) back = true;
    Sp = S;
  }
  ++tally.rays;
  tally.slope_falls += falls;
  tally.turns_back += back;
  tally.start_falling += S0 < -1e-9 * slope_scale;
}

// The total in the plane of a term pair: Psi_I(x) + Psi_J(y) + Psi_IJ(x, y) (ti, tj may be
// null). Rays from the 2D table's box to that box scaled 3x about its centre; one in five from a
// corner in a random direction of its quadrant, the others along the outward normal of a random
// edge point. Corner rays of corners that `pc` reports are skipped (counted).
inline RayTally pair_plane_rays(const BakedTerm& t, const BakedTerm* ti, const BakedTerm* tj, const PairCheck& pc,
                                int rays, unsigned seed) {
  RayEnergy E = [&](const std::vector<double>& x, const std::vector<double>& v, double& F, double& S) {
    const BakedJet2 j = eval_baked_2d(t, {x[0], x[1]});
    F = j.f;
    S = j.g[0] * v[0] + j.g[1] * v[1];
    if (ti) {
      const BakedJet1 a = eval_baked_1d(*ti, x[0]);
      F += a.f;
      S += a.df * v[0];
    }
    if (tj) {
      const BakedJet1 b = eval_baked_1d(*tj, x[1]);
      F += b.f;
      S += b.df * v[1];
    }
  };
  const double H[2] = {0.5 * (t.hi[0] - t.lo[0]), 0.5 * (t.hi[1] - t.lo[1])};
  double slope_scale = 0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const std::vector<double> x = {t.lo[0] + 2 * H[0] * i / 20, t.lo[1] + 2 * H[1] * j / 20};
      double F, Sx, Sy;
      E(x, {H[0], 0}, F, Sx);
      E(x, {0, H[1]}, F, Sy);
      slope_scale = std::max(slope_scale, std::abs(Sx) + std::abs(Sy));
    }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  RayTally tally;
  for (int r = 0; r < rays; ++r) {
    std::vector<double> p(2), v(2);
    if (r % 5 == 0) {
      const int c = int(U(rng) * 4) & 3;
      const double sx = (c & 1) ? 1 : -1, sy = (c & 2) ? 1 : -1, ang = 0.5 * M_PI * U(rng);
      p = {sx > 0 ? t.hi[0] : t.lo[0], sy > 0 ? t.hi[1] : t.lo[1]};
      v = {sx * H[0] * std::cos(ang), sy * H[1] * std::sin(ang)};
      ++tally.corner_rays;
      if (pc.corner_bends[c]) {
        ++tally.skipped;
        continue;
      }
    } else {
      const int e = int(U(rng) * 4) & 3, axis = e / 2, along = 1 - axis;
      const double sg = (e % 2) ? 1 : -1;
      p[axis] = sg > 0 ? t.hi[axis] : t.lo[axis];
      p[along] = t.lo[along] + 2 * H[along] * (0.001 + 0.998 * U(rng));
      v[axis] = sg * H[axis];
      v[along] = 0;
    }
    double tmax = 1e300;
    for (int k = 0; k < 2; ++k)
      if (v[k] != 0) tmax = std::min(tmax, 2 * H[k] / std::abs(v[k]));
    walk_ray(E, p, v, tmax, slope_scale, tally);
  }
  return tally;
}

}  // namespace yarnhom::test
