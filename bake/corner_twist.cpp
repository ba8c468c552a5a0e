#include "bake/corner_twist.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bake/bake_accuracy.hpp"
#include "bake/pair_check.hpp"

namespace yarnhom {

std::string CornerTwistRepair::summary() const {
  std::string out;
  char buf[256];
  for (int c = 0; c < 4; ++c)
    if (repaired[c]) {
      std::snprintf(buf, sizeof buf, "%s%s twist %.3g raised to %.3g (1D curvatures %.3g, %.3g)", out.empty() ? "" : ", ",
                    kBakedCornerNames[c] + 7, twist_before[c], twist_after[c], k_first[c], k_second[c]);
      out += buf;
    }
  if (out.empty()) return out;
  std::snprintf(buf, sizeof buf, "; corner cells changed by at most %.2g (%.2g%% of the range), gradient by %.2g", max_change,
                range > 0 ? 100 * max_change / range : 0.0, max_grad_change);
  return "corner twist repair: " + out + buf;
}

CornerTwistRepair repair_corner_twists(BakedTable& t2, const BakedTerm* ti, const BakedTerm* tj, double gamma) {
  CornerTwistRepair r;
  if (t2.dim() != 2 || t2.extrapolation == kBakedLinear) return r;
  const auto [lo, hi] = std::minmax_element(t2.f.begin(), t2.f.end());
  r.range = *hi - *lo;
  const BakedTerm before = make_baked_term(t2);
  const PairCheck pc = check_pair(before, ti, tj);
  const int n0 = t2.knots[0], n1 = t2.knots[1];
  for (int c = 0; c < 4; ++c) {
    const double sx = c & 1 ? 1.0 : -1.0, sy = c & 2 ? 1.0 : -1.0;
    r.twist_before[c] = r.twist_after[c] = pc.twist[c];
    r.k_first[c] = pc.k_first[c];
    r.k_second[c] = pc.k_second[c];
    const double limit = -gamma * std::sqrt(std::max(pc.k_first[c], 0.0) * std::max(pc.k_second[c], 0.0));
    if (!(pc.twist[c] < limit)) continue;
    r.repaired[c] = true;
    r.twist_after[c] = limit;
    const int i = c & 1 ? n0 - 1 : 0, j = c & 2 ? n1 - 1 : 0;
    t2.f_xy[size_t(i) * n1 + j] = sx * sy * limit;  // the knot's f_xy is the corner's D11 exactly
  }
  if (!r.any()) return r;
  compute_safeguard(t2);
  // Measure the change on the corner cells (the only cells a corner knot enters).
  const BakedTerm after = make_baked_term(t2);
  for (int c = 0; c < 4; ++c) {
    if (!r.repaired[c]) continue;
    const double hx = t2.spacing(0), hy = t2.spacing(1);
    const double lo[2] = {c & 1 ? t2.upper[0] - hx : t2.lower[0], c & 2 ? t2.upper[1] - hy : t2.lower[1]};
    const double hi[2] = {lo[0] + hx, lo[1] + hy};
    max_table_change(before, after, lo, hi, 8, 8, r.max_change, r.max_grad_change);
  }
  return r;
}

}  // namespace yarnhom
