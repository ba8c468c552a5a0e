#pragma once
// Where a continuum strip leaves its material's data. `sim stretch` records the in-plane strain
// of the strip's middle per test (stretch.csv: middle_s_x, middle_s_a, middle_s_y); the baked
// 1D terms 0, 1 and 2 carry the boxes their data were sampled in. Where the middle comes within
// 1 % of a box's width of a bound, or passes it, the energy there is the bake's safeguard (a
// continuation that only rises outward, docs/bake.md), not data: the continuum's answer from
// that test on is the continuation's, and the data must be sampled wider (`produce --ranges`).
// Measured on the slip-stitch honeycomb's course strip: the yarn strip contracts to s_y = -0.44
// at 170 %, the default box stops at -0.2, and the continuum, held there from 140 %, came out
// twice as stiff at 170 % (docs/accuracy.md).
#include <string>
#include <vector>

#include "core/baked.hpp"

namespace yarnhom {

struct BoxReach {
  int component = 0;      // 0 s_x, 1 s_a, 2 s_y
  bool upper = false;     // which bound
  double bound = 0;       // the box's bound (the baked 1D term's lower or upper)
  size_t first = 0;       // the first test whose middle reached it
  double value = 0;       // the middle's strain there
  double extreme = 0;     // the farthest the middle went towards / past that bound
};

// middle[c][k]: component c (s_x, s_a, s_y) of the middle at test k. Components whose 1D term
// the material lacks, or whose column is empty, are skipped. One entry per bound reached.
std::vector<BoxReach> box_reach(const BakedModel& m, const std::vector<std::vector<double>>& middle);

// One line per entry, e.g. "the middle's s_y reached the data box's lower bound -0.2 at test 9
// (-0.2041; at most -0.2049): from there the material is the bake's continuation, not data";
// stretch[k] gives the test's ratio in the text. Empty when nothing was reached.
std::string box_reach_text(const std::vector<BoxReach>& r, const std::vector<double>& stretch);

}  // namespace yarnhom
