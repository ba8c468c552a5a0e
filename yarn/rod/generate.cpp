#include "yarn/rod/generate.hpp"

#include "yarn/rod/pattern_build.hpp"

#include <cmath>
#include <stdexcept>

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

namespace {

// The paper's patterns (Sperl et al. 2021, used by Feng et al. 2024) at their scale: yarn radius
// 1 mm, the periods of the published tiles. Shape parameters in radii, chosen so that the
// generated tile's yarn length and relaxed rest energy match the published tile
// (tests/yarn/rod/test_paper_patterns.cpp compares them).
Pattern paper_basket() {
  const double r = 1e-3;
  WeaveParams p;
  p.name = "basket";
  p.radius = r;
  p.px = 10.7037e-3;
  p.py = 10.3e-3;
  p.weave = {"1100", "1100", "0011", "0011"};
  p.weft_amplitude = 1.455 * r;
  p.warp_amplitude = 1.325 * r;
  p.flatness = 1.0 / 6;
  p.samples_weft = p.samples_warp = 10;
  return generate_weave(p);
}

Pattern paper_satin() {
  const double r = 1e-3;
  WeaveParams p;
  p.name = "satin";
  p.radius = r;
  p.px = 11.1111e-3;
  p.py = 11.0185e-3;
  // Five-harness satin: weft i passes over warp 3i mod 5 only.
  for (int i = 0; i < 5; ++i) {
    std::string row(5, '0');
    row[(3 * i) % 5] = '1';
    p.weave.push_back(row);
  }
  p.weft_amplitude = p.warp_amplitude = 2.12 * r;
  p.float_lift = 1.5 * r;
  p.samples_weft = p.samples_warp = 13;
  return generate_weave(p);
}

// One loop of the published 2 x 2-loop tile (15.05 x 7.93 mm): the same fabric, a quarter of
// the unknowns.
Pattern paper_stockinette() {
  const double r = 1e-3;
  StockinetteParams p;
  p.radius = r;
  p.wale = 15.0513e-3 / 2;
  p.course = 7.93099e-3 / 2;
  p.loop_height = 3.3 * r;
  p.depth = 0.975 * r;
  p.bulb = 1.7;
  p.waist = -0.2 * r;
  p.samples = 24;
  p.rest_from_shape = true;
  return generate_stockinette(p);
}

}  // namespace

std::vector<std::string> builtin_pattern_names() { return {"basket", "plain", "satin", "stockinette"}; }

bool is_builtin_pattern(const std::string& name) {
  for (const auto& n : builtin_pattern_names())
    if (n == name) return true;
  return false;
}

std::string builtin_pattern_list() {
  std::string names;
  for (const auto& n : builtin_pattern_names()) names += (names.empty() ? "" : ", ") + n;
  return names;
}

Pattern builtin_pattern(const std::string& name) {
  if (name == "basket") return paper_basket();
  if (name == "plain") {
    WovenParams p;
    p.group = 1;
    return generate_woven(p);
  }
  if (name == "satin") return paper_satin();
  if (name == "stockinette") return paper_stockinette();
  throw std::invalid_argument("unknown built-in pattern '" + name + "' (known: " + builtin_pattern_list() + ")");
}

}  // namespace yarnhom::yarn
