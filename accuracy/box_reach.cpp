#include "accuracy/box_reach.hpp"

#include <algorithm>
#include <cstdio>

namespace yarnhom {

std::vector<BoxReach> box_reach(const BakedModel& m, const std::vector<std::vector<double>>& middle) {
  static const char* kTerm[3] = {"0", "1", "2"};
  std::vector<BoxReach> out;
  for (int c = 0; c < 3 && c < int(middle.size()); ++c) {
    const BakedTable* t = m.find(kTerm[c]);
    if (!t || t->lower.empty() || middle[c].empty()) continue;
    const double lo = t->lower[0], hi = t->upper[0], tol = 0.01 * (hi - lo);
    for (const bool upper : {false, true}) {
      const double b = upper ? hi : lo;
      BoxReach r;
      bool found = false;
      for (size_t k = 0; k < middle[c].size(); ++k) {
        const double v = middle[c][k];
        const bool at = upper ? v >= b - tol : v <= b + tol;
        if (!at) continue;
        if (!found) {
          found = true;
          r.component = c, r.upper = upper, r.bound = b, r.first = k, r.value = v, r.extreme = v;
        }
        r.extreme = upper ? std::max(r.extreme, v) : std::min(r.extreme, v);
      }
      if (found) out.push_back(r);
    }
  }
  return out;
}

std::string box_reach_text(const std::vector<BoxReach>& r, const std::vector<double>& stretch) {
  static const char* kName[3] = {"s_x", "s_a", "s_y"};
  std::string s;
  char buf[400];
  for (const BoxReach& b : r) {
    const double ratio = b.first < stretch.size() ? stretch[b.first] : 0.0;
    std::snprintf(buf, sizeof buf,
                  "the strip's middle reached the data box's %s bound %s = %g at %.0f %% (%.4g; at most %.4g): from "
                  "there on the material is the bake's continuation, not data (sample wider: produce --ranges)",
                  b.upper ? "upper" : "lower", kName[b.component], b.bound, 100 * ratio, b.value, b.extreme);
    s += std::string(s.empty() ? "" : "\n") + buf;
  }
  return s;
}

}  // namespace yarnhom
