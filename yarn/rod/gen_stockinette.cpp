// Weft-knitted stockinette, one loop per tile (StockinetteParams, generate.hpp).
#include "yarn/rod/generate.hpp"

#include <cmath>
#include <stdexcept>

#include "yarn/rod/pattern_build.hpp"

namespace yarnhom::yarn {

Pattern generate_stockinette(const StockinetteParams& prm) {
  if (!(prm.radius > 0)) throw std::invalid_argument("stockinette: radius must be positive");
  const double r = prm.radius;
  const double w = prm.wale > 0 ? prm.wale : 7.2 * r, h = prm.course > 0 ? prm.course : 4.4 * r;
  const double b = prm.loop_height > 0 ? prm.loop_height : 3.2 * r, c = prm.depth > 0 ? prm.depth : 1.2 * r;
  if (prm.samples < 8) throw std::invalid_argument("stockinette: at least 8 samples per loop");
  Pattern pat;
  pat.name = "stockinette";
  pat.px = w;
  pat.py = h;
  pat.radius = r;
  std::vector<Eigen::Vector3d> pts;
  for (int k = 0; k < prm.samples; ++k) {
    const double th = -M_PI + 2 * M_PI * k / prm.samples;
    pts.emplace_back(w / (2 * M_PI) * (th + prm.bulb * std::sin(2 * th)), b * std::cos(th) + prm.waist * std::cos(3 * th),
                     -c * std::cos(2 * th));
  }
  add_yarn(pat, pts, {1, 0});
  if (prm.rest_from_shape)
    set_rest_to_shape(pat);
  else
    complete_rest_state(pat);
  return pat;
}

}  // namespace yarnhom::yarn
