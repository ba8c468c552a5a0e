#include "bake/bake_accuracy.hpp"

#include <algorithm>
#include <cmath>

namespace yarnhom {

BakeDeviation bake_deviation(const TermFunction& reference, const TermFunction& baked, int d,
                             const std::vector<double>& lower, const std::vector<double>& upper, int grid) {
  if (grid <= 0) grid = d == 1 ? 2003 : 203;
  // Cell midpoints of a grid with a prime-ish count: never on the knots of a 100/150/200 table.
  auto coord = [&](int axis, int k) { return lower[axis] + (upper[axis] - lower[axis]) * (k + 0.5) / grid; };
  const int n = d == 1 ? grid : grid * grid;
  std::vector<double> s(size_t(n) * d);
  for (int p = 0; p < n; ++p) {
    if (d == 1) s[p] = coord(0, p);
    else { s[2 * p] = coord(0, p / grid); s[2 * p + 1] = coord(1, p % grid); }
  }
  auto a = reference(s.data(), n, 1), b = baked(s.data(), n, 1);
  BakeDeviation r;
  double lo = a[0], hi = a[0], gmax = 0, gdev = 0;
  for (int p = 0; p < n; ++p) {
    lo = std::min(lo, a[p]);
    hi = std::max(hi, a[p]);
    const double e = std::abs(a[p] - b[p]);
    r.max_abs = std::max(r.max_abs, e);
    r.mean_abs += e / n;
    double g2 = 0, dg2 = 0;
    for (int i = 0; i < d; ++i) {
      const double ga = a[size_t(1 + i) * n + p], gb = b[size_t(1 + i) * n + p];
      g2 += ga * ga;
      dg2 += (ga - gb) * (ga - gb);
    }
    gmax = std::max(gmax, std::sqrt(g2));
    gdev = std::max(gdev, std::sqrt(dg2));
  }
  r.range = hi - lo;
  const double scale = r.range > 0 ? r.range : 1.0;
  r.max_rel = r.max_abs / scale;
  r.mean_rel = r.mean_abs / scale;
  r.grad_max_rel = gmax > 0 ? gdev / gmax : 0.0;
  return r;
}

void max_table_change(const BakedTerm& before, const BakedTerm& after, const double lo[2], const double hi[2], int n0,
                      int n1, double& max_value, double& max_gradient) {
  for (int a = 0; a <= n0; ++a)
    for (int b = 0; b <= n1; ++b) {
      const double s[2] = {lo[0] + (hi[0] - lo[0]) * a / n0, lo[1] + (hi[1] - lo[1]) * b / n1};
      double p[3], q[3];
      eval_baked_jet(before, s, 1, p);
      eval_baked_jet(after, s, 1, q);
      max_value = std::max(max_value, std::abs(q[0] - p[0]));
      max_gradient = std::max(max_gradient, std::hypot(q[1] - p[1], q[2] - p[2]));
    }
}

}  // namespace yarnhom
