// The tiny plain and basket weaves of WovenParams (generate.hpp), straight yarn at rest.
#include "yarn/rod/generate.hpp"

#include <cmath>
#include <stdexcept>

#include "yarn/rod/pattern_build.hpp"

namespace yarnhom::yarn {

Pattern generate_woven(const WovenParams& prm) {
  if (prm.group < 1 || prm.group > 2) throw std::invalid_argument("woven: group must be 1 (plain) or 2 (basket)");
  if (!(prm.radius > 0)) throw std::invalid_argument("woven: radius must be positive");
  const double r = prm.radius, a = prm.spacing > 0 ? prm.spacing : 4 * r;
  if (a < 2.5 * r) throw std::invalid_argument("woven: spacing must be at least 2.5 radii");
  const int g = prm.group, m = prm.samples_per_spacing, ny = 2 * g;
  Pattern pat;
  pat.name = g == 1 ? "plain" : "basket";
  pat.px = pat.py = 2 * g * a;
  pat.radius = r;
  // Crossing heights +-r (centrelines 2r apart: touching); c_g lifts the profile so that the
  // outermost crossing of a group sits at exactly r.
  const double cg = 1.0 / std::cos(M_PI * (g - 1) / (2.0 * g));
  const double L = pat.px, start = -L / 2, centre = -L / 2 + a / 2 + (g - 1) * a / 2;
  const int N = m * ny;
  for (int k = 0; k < ny; ++k) {  // wefts along x, at y_k
    const double y = -L / 2 + (k + 0.5) * a;
    std::vector<Eigen::Vector3d> pts;
    for (int j = 0; j < N; ++j) {
      const double x = start + L * j / N;
      pts.emplace_back(x, y, r * cg * std::cos(M_PI * (x - centre) / (g * a) + M_PI * (k / g)));
    }
    add_yarn(pat, pts, {1, 0});
  }
  for (int i = 0; i < ny; ++i) {  // warps along y, at x_i
    const double x = -L / 2 + (i + 0.5) * a;
    std::vector<Eigen::Vector3d> pts;
    for (int j = 0; j < N; ++j) {
      const double y = start + L * j / N;
      pts.emplace_back(x, y, -r * cg * std::cos(M_PI * (y - centre) / (g * a) + M_PI * (i / g)));
    }
    add_yarn(pat, pts, {0, 1});
  }
  complete_rest_state(pat);
  return pat;
}

}  // namespace yarnhom::yarn
