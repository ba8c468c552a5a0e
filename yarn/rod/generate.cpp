// The built-in patterns: the paper's at the paper's scale, and the tiny plain weave.
#include "yarn/rod/generate.hpp"

#include <cmath>
#include <stdexcept>

#include "yarn/rod/pattern_build.hpp"

namespace yarnhom::yarn {

namespace {

// The paper's patterns (Sperl et al. 2021, used by Feng et al. 2024) at their scale: yarn radius
// 1 mm, the periods of the published tiles. Shape parameters in radii, chosen so that the
// generated tile's yarn length and relaxed rest energy match the published tile
// (tests/yarn/rod/test_paper_patterns.cpp compares them). The basket's amplitudes put its crossings just at contact: its
// Psi0 (6e-5 J/m^2, like the published tile's) changes by orders of magnitude within +-0.03 r.
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
  // Each yarn lies low and flat on its side of the cloth and rises to its interlacing in a
  // narrow peak (peak = 2), like the published tile's (weft: +1.1 r over its warp, a floor at
  // -2.3 r). A cosine profile (peak = 1) slopes each yarn through the crossings beside its
  // interlacing, where the relaxation then presses the yarns apart (rest energy 0.033 against
  // 0.012 J/m^2). The amplitude sets the contact: Psi0 halves for +0.03 r.
  p.weft_amplitude = p.warp_amplitude = 1.769 * r;
  p.float_lift = 1.0 * r;
  p.peak = 2;
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

// The slip stitch honeycomb: two wales, four courses, each course one yarn. Courses 0 and 2
// purl one wale and slip the other with the yarn on the purl side (+z), courses 1 and 3 knit
// both: each slipped loop is held up through the slipping course (the honeycomb's long loops,
// floats across them). Shape parameters in radii, from a coordinate search on the rest energy
// of the unspaced sketch (the earlier shape, loop height 3.18, depth 0.8, bulb 1.78, floats at
// 3.6 r, relaxed 15 % shorter along the wale to 0.56 J/m^2: its loops pressed into each other).
// The sketch passes through itself (46 segment pairs closer than one radius, 0.75 r at the
// closest); it is spaced (space_yarns, yarn_spacing.hpp) to 1.62 r between centrelines, without
// smoothing: the closest pair then 1.61 r apart (1.90 r relaxed; the published tile 1.87 r stored),
// yarn 183.0 against the published 178.2 mm (unspaced 184.1), Psi0 0.325 against 0.321 J/m^2.
// The rest energy falls as the spacing grows (1.55 r: 0.39, 1.6 r: 0.35, 1.65 r: 0.29, 1.7 r:
// 0.24, 2 r: 0.034 J/m^2, the yarn 194.8 mm): the spacing is the parameter that sets it. The tile
// still has two rest shapes close together (the lower legs of the knit courses' loops over the
// purl loops below settle further back or not: z -4.0..4.0 r, 3.5 % shorter along the wale, or
// -4.7..4.3 r, 2 % shorter), but spaced they are at one energy: edges 5 % shorter to 5 % longer
// (194-176 vertices) give 0.313-0.334 J/m^2, where the unspaced sketch gave 0.55-0.56 for all but
// its own sampling (docs/rve.md, "Where the energy sits").
Pattern paper_slip_stitch_honeycomb() {
  const double r = 1e-3;
  KnitParams p;
  p.name = "slip_stitch_honeycomb";
  p.radius = r;
  p.px = 10.9376e-3;
  p.py = 12.4184e-3;
  p.chart = {"PS", "KK", "SP", "KK"};
  p.bulb = 1.878;
  p.loop_height = 3.377 * r;
  p.depth = 1.0 * r;
  p.head_depth = 3.6 * r;
  p.sinker_gap = 2.5 * r;
  p.float_depth = 3.796 * r;
  p.waist = -0.104 * r;
  p.float_lift = -0.047 * r;
  p.edge = 1.0 * r;
  p.spacing = 1.62 * r;
  return generate_knit(p);
}

// The cartridge belt rib (Walker's: a garter ground, every course slipping one wale in four,
// the slips of consecutive courses two wales apart): courses alternately purl and knit (as seen
// from +z), the purl course slipping wale 1, the knit course wale 3. Each slipped wale's loop is
// held up through the slipping course (the ribs' long loops, their legs at held_depth in front of
// the float across them, as in the published tile: legs at 5.5 r, floats at 3.1 r), the float on
// the face the course holds its yarn on. Two courses: half the published four-course tile (whose
// courses 2 and 3 repeat 0 and 1, the yarn running the other way). The loops are drawn as a sketch
// that passes through itself (88 segment pairs closer than one radius, the closest 0.57 r apart,
// where contact wants 2 r and the published tile has none closer than 1.9 r: each loop's legs
// below mid-height, the floats through the held loops' legs, the held heads on the far face;
// docs/rve.md "Where the energy sits"), then spaced (space_yarns, yarn_spacing.hpp): every pair of
// segments closer than 2 r pushed apart, the moves averaged along the yarn and capped so that no
// yarn passes through another, with a smoothing of 0.071 per round (a curve-shortening flow). The
// generated curve then has no pair closer than 1.62 r (none closer than one radius), 1.83 r after
// relaxation. The yarn is 331.9 mm per four courses against the published 334.0 (-0.6 %), Psi0
// 0.764 against 0.772 J/m^2 (stretch 0.33, bend 0.22, twist 0.02, contact 0.20, where the
// published tile's is 0.145, 0.501, 0.010, 0.116: the total matches, its split does not: the
// smoothing shortens the yarn, which the relaxation stretches back), the tile relaxed by (+0.115,
// -0.010, +0.055) (published +0.056, -0.053, +0.039). The smoothing sets the rest energy: 0
// gives 0.029 (the yarn 416 mm), 0.05 0.36, 0.08 0.99, 0.09 1.31 J/m^2; edges 5 % shorter or
// longer, 0.70 and 0.84. Unspaced, the sketch relaxes to 1.45 J/m^2 (1.80 before leg_spread 0.8 r).
Pattern paper_cartridge_belt_rib() {
  const double r = 1e-3;
  KnitParams p;
  p.name = "cartridge_belt_rib";
  p.radius = r;
  p.px = 17.4261e-3;
  p.py = 11.6613e-3 / 2;
  p.chart = {"PSPP", "KKKS"};
  p.loop_height = 2.8 * r;
  p.depth = 0.6 * r;
  p.head_depth = 2.75 * r;
  p.held_depth = 4.75 * r;
  p.bulb = 1.925;
  p.sinker_gap = 2.1 * r;
  p.float_depth = 3.4 * r;
  p.float_lift = -0.4 * r;
  p.leg_spread = 0.8 * r;
  p.edge = 1.0 * r;
  p.spacing = 2.0 * r;
  p.spacing_smoothing = 0.071;
  return generate_knit(p);
}

}  // namespace

std::vector<std::string> builtin_pattern_names() {
  return {"basket", "cartridge_belt_rib", "plain", "satin", "slip_stitch_honeycomb", "stockinette"};
}

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
  if (name == "cartridge_belt_rib") return paper_cartridge_belt_rib();
  if (name == "plain") {
    WovenParams p;
    p.group = 1;
    return generate_woven(p);
  }
  if (name == "satin") return paper_satin();
  if (name == "slip_stitch_honeycomb") return paper_slip_stitch_honeycomb();
  if (name == "stockinette") return paper_stockinette();
  throw std::invalid_argument("unknown built-in pattern '" + name + "' (known: " + builtin_pattern_list() + ")");
}

}  // namespace yarnhom::yarn
