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
};
Pattern generate_stockinette(const StockinetteParams& p);

// "basket", "plain", "stockinette": the built-in patterns with default parameters.
std::vector<std::string> builtin_pattern_names();
bool is_builtin_pattern(const std::string& name);
Pattern builtin_pattern(const std::string& name);  // throws std::invalid_argument, naming them

}  // namespace yarnhom::yarn
