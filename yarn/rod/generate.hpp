#pragma once
// Procedural periodic yarn patterns, so the project ships its own and runs where the paper's
// are absent. Geometry is an initial guess: straight, untwisted yarn at rest (RK = RT = 0,
// RL = the generated edge lengths), to be relaxed to equilibrium (relax.hpp) before use.
#include <string>
#include <vector>

#include "yarn/rod/pattern.hpp"

namespace yarnhom::yarn {

// Woven: warp yarns along y, weft yarns along x, crossing on a square grid of pitch
// `spacing`. Each yarn passes over `group` crossing yarns, then under `group` (group 1: plain
// weave, group 2: the 2x2 basket weave). One tile holds 2*group yarns each way.
struct WovenParams {
  double radius = 1e-4;          // m
  double spacing = 0.0;          // m, centre-to-centre of parallel yarns; 0: 4 radii
  int group = 2;                 // 1 or 2
  int samples_per_spacing = 4;   // vertices per yarn between two crossings
};
Pattern generate_woven(const WovenParams& p);

// Weft-knitted stockinette: one course of loops per tile, one loop per wale, the yarn's
// centreline  x = w/(2 pi) (th + a sin 2th),  y = b cos th,  z = -c cos 2th  (th in [-pi, pi):
// head at th = 0, sinker loops at th = +-pi; legs at the front, heads and sinkers behind, so
// each head holds the legs of the loop above).
struct StockinetteParams {
  double radius = 1e-4;       // m
  double wale = 0.0;          // loop width w = px (m); 0: 7.2 radii
  double course = 0.0;        // course height py (m); 0: 4.4 radii
  double loop_height = 0.0;   // b (m); 0: 3.2 radii
  double depth = 0.0;         // c (m); 0: 1.2 radii
  double bulb = 1.1;          // a: how far the head overhangs the legs
  int samples = 16;           // vertices per loop
  double waist = 0.0;         // m: y += waist cos 3th (narrows the loop's neck where < 0)
  bool rest_from_shape = false;  // rest state: the generated shape (set_rest_to_shape), else straight
};
Pattern generate_stockinette(const StockinetteParams& p);

// A woven tile from its weave matrix: weft i (along x, i = 0 at the bottom) passes over warp j
// (along y, j = 0 at the left) where weave[i][j] is '1'. Parallel yarns are evenly spaced; a
// yarn's height is the lift times the mean of its sides (+1 over, -1 under: a float rides
// high) plus the amplitude times the fundamental harmonic of its over/under sequence (flattened by
// its third harmonic where `flatness` > 0). The rest
// state is the generated shape (set_rest_to_shape): yarn set by weaving, which the relaxation
// at rest then presses into contact. gen_weave.cpp.
struct WeaveParams {
  std::string name = "weave";
  double radius = 1e-3;             // m
  double px = 0, py = 0;            // tile periods (m)
  std::vector<std::string> weave;   // rows of '0'/'1', one per weft
  double weft_amplitude = 0, warp_amplitude = 0;  // m
  double float_lift = 0;            // m
  double flatness = 0;              // k in [0, 1/6]: the profile (cos - k cos 3) / (1 - k), flat-topped floats
  double peak = 1;                  // p >= 1: a yarn mostly under (over) the others rises (dips) to its
                                    // interlacings as 2 ((1 + cos) / 2)^p - 1 (mirrored), flatter elsewhere
  int samples_weft = 0, samples_warp = 0;  // vertices per yarn; 0: about one per 1.2 radii
};
Pattern generate_weave(const WeaveParams& p);

// A weft knit from its stitch chart: courses bottom to top (one yarn each, along +x), one
// character per wale: 'K' knit, 'P' purl (as seen from +z), 'S' slipped (the yarn floats across
// the wale float_depth from the mid-plane, on the face the course holds its yarn on: in front
// (+z) after a purl, behind after a knit; the loop below is held up to the next course that
// works the wale, its legs at held_depth). Each loop is generate_stockinette's shape in its wale (w = px / wales) and course
// (h = py / courses): legs at +depth (knit) or -depth (purl), the head at head_depth on the
// side away from the legs of the stitch that catches it, the sinkers sinker_gap behind (knit) or
// in front of (purl) the legs of the loop the stitch is pulled through. The rest state is the
// generated shape (set_rest_to_shape). gen_knit.cpp.
struct KnitParams {
  std::string name = "knit";
  double radius = 1e-3;             // m
  double px = 0, py = 0;            // tile periods (m)
  std::vector<std::string> chart;   // courses of 'K', 'P', 'S', bottom first
  double loop_height = 0;           // b (m): the loop spans y_k -+ b
  double depth = 0;                 // c (m): the legs at +-c
  double head_depth = 0;            // m: the heads at +-head_depth (0: depth)
  double held_depth = 0;            // m: the legs of a loop held through slipping courses at
                                    // +-held_depth (0: depth), in front of the floats across it
  double held_height = 1;           // a held loop's head rises this fraction of the courses it is
                                    // held through above an ordinary loop's
  double held_bulb = 0;             // a of the held loops (0: bulb)
  double held_head_gap = 0;         // m: where the stitch that catches a loop is held itself (legs
                                    // at held_depth), the head lies this far from those legs on the
                                    // side away from them (0: at head_depth, as for any loop: on the
                                    // far face when head_depth < held_depth)
  double bulb = 1.0;                // a: how far the head overhangs the legs
  double waist = 0;                 // m, as in StockinetteParams
  double leg_spread = 0;            // m: x += leg_spread sin th: each leg moves out by up to this
                                    // (at mid-height, th = +-pi/2), the head's tip and the sinkers
                                    // stay; with a large bulb a loop's legs come close below mid-height
  double float_depth = 0;           // m: a float's distance from the mid-plane (its face: above)
  double float_lift = 0;            // m: a float's rise above the sinkers at mid-wale
  double sinker_gap = 0;            // m: sinkers from the legs they pass (0: 2 depths)
  double edge = 1e-3;               // m: about the edge length of the sampled yarn
  double spacing = 0;               // m: > 0: the sampled yarns spaced by space_yarns to this
                                    // distance between centrelines (yarn_spacing.hpp), keeping
                                    // their crossings; 0: the sketch as drawn
  double spacing_smoothing = 0;     // the smoothing of space_yarns, in [0, 0.5) (it shortens the yarn)
};
Pattern generate_knit(const KnitParams& p);

// The built-in patterns: "plain" (the tiny 0.1 mm plain weave above, straight yarn at rest) and
// the paper's patterns generated at the paper's scale (1 mm yarn radius, the periods of the
// published tiles; the rest state the generated shape): "basket", "cartridge_belt_rib" (two
// courses of the published four), "satin", "slip_stitch_honeycomb" and "stockinette".
std::vector<std::string> builtin_pattern_names();
bool is_builtin_pattern(const std::string& name);
Pattern builtin_pattern(const std::string& name);  // throws std::invalid_argument, naming them
std::string builtin_pattern_list();                // "basket, plain, ...": for messages and --help

}  // namespace yarnhom::yarn
