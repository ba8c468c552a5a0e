#include "bake/edge_slope_repair.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bake/bake_accuracy.hpp"

namespace yarnhom {

std::string EdgeSlopeRepair::summary() const {
  std::string out;
  char buf[256];
  for (int e = 0; e < 4; ++e)
    if (knots_raised[e] || cross_zeroed[e]) {
      std::snprintf(buf, sizeof buf, "%s%s: outward slope raised to >= 0 at %d knots (down to %.3g before), %d cross derivatives "
                    "set to 0", out.empty() ? "" : ", ", kBakedEdgeNames[e] + 5, knots_raised[e], worst_before[e], cross_zeroed[e]);
      out += buf;
    }
  if (out.empty()) return out;
  std::snprintf(buf, sizeof buf, "; outer cell layer changed by at most %.2g (%.2g%% of the range), gradient by %.2g", max_change,
                range > 0 ? 100 * max_change / range : 0.0, max_grad_change);
  return "edge slope repair (the total fell outward): " + out + buf;
}

namespace {

// Cubic Hermite basis on [0, 1].
double h00(double t) { return (1 + 2 * t) * (1 - t) * (1 - t); }
double h01(double t) { return t * t * (3 - 2 * t); }
double h10(double t) { return t * (1 - t) * (1 - t); }
double h11(double t) { return t * t * (t - 1); }

// The lowest value on [0, 1] of the cubic Hermite with end values a, b and end slopes ma, mb:
// the ends and the stationary points inside (roots of the derivative 3 A t^2 + 2 B t + ma). A
// grid of samples alone misses a dip confined between its last point and an end (a knot at S = 0
// with its slope pointing down into the cell: measured, a trained stocktiny term's corner cell).
double hermite_min(double a, double b, double ma, double mb) {
  auto at = [&](double t) { return a * h00(t) + b * h01(t) + ma * h10(t) + mb * h11(t); };
  double lowest = std::min(a, b);
  const double A = 2 * a - 2 * b + ma + mb, B = -3 * a + 3 * b - 2 * ma - mb;
  auto visit = [&](double t) {
    if (t > 0 && t < 1) lowest = std::min(lowest, at(t));
  };
  const double disc = B * B - 3 * A * ma;
  if (A != 0 && disc >= 0) {
    const double r = std::sqrt(disc);
    visit((-B + r) / (3 * A));
    visit((-B - r) / (3 * A));
  } else if (A == 0 && B != 0) {
    visit(-ma / (2 * B));
  }
  for (int k = 1; k < 32; ++k) lowest = std::min(lowest, at(k / 32.0));  // rounding near double roots
  return lowest;
}

}  // namespace

EdgeSlopeRepair repair_edge_slopes(BakedTable& t2, const BakedTerm* ti, const BakedTerm* tj) {
  EdgeSlopeRepair r;
  if (t2.dim() != 2 || t2.extrapolation == kBakedLinear) return r;
  const auto [lo, hi] = std::minmax_element(t2.f.begin(), t2.f.end());
  r.range = *hi - *lo;
  const BakedTable original = t2;
  const int n[2] = {t2.knots[0], t2.knots[1]};
  const BakedTerm* one[2] = {ti, tj};
  auto index = [&](int i, int j) { return size_t(i) * n[1] + j; };
  // The scale of a slope, for rounding: the largest stored normal derivative or 1D end slope.
  double scale = 0;
  for (double v : t2.f_x) scale = std::max(scale, std::abs(v));
  for (double v : t2.f_y) scale = std::max(scale, std::abs(v));
  const double tol = 1e-12 * (1 + scale);
  for (int e = 0; e < 4; ++e) {
    const int axis = e / 2, along = 1 - axis;
    const double sigma = e % 2 ? 1.0 : -1.0, X = e % 2 ? t2.upper[axis] : t2.lower[axis];
    const double s1d = one[axis] ? eval_baked_1d(*one[axis], X).df : 0.0;
    std::vector<double>& fn = axis == 0 ? t2.f_x : t2.f_y;
    const int fixed = e % 2 ? n[axis] - 1 : 0, m = n[along];
    auto knot = [&](int j) { return axis == 0 ? index(fixed, j) : index(j, fixed); };
    auto S = [&](int j) { return sigma * (fn[knot(j)] + s1d); };
    std::vector<char> raised(m, 0);
    // 1. Knots.
    for (int j = 0; j < m; ++j)
      if (S(j) < -tol) {
        r.worst_before[e] = std::min(r.worst_before[e], S(j));
        fn[knot(j)] = -s1d;
        raised[j] = 1;
      }
    // 2. Between knots: S(t) on cell c is the cubic Hermite of S(c), S(c+1) with slopes
    //    sigma h f_xy (t along the edge, increasing with the along coordinate).
    const double h = t2.spacing(along);
    for (int pass = 0; pass <= m + 2; ++pass) {
      bool dipped = false;
      for (int c = 0; c + 1 < m; ++c) {
        const double a = S(c), b = S(c + 1), ma = sigma * h * t2.f_xy[knot(c)], mb = sigma * h * t2.f_xy[knot(c + 1)];
        if (hermite_min(a, b, ma, mb) >= -tol) continue;
        dipped = true;
        for (int j : {c, c + 1}) {
          const bool corner = j == 0 || j == m - 1;
          if (!corner) {
            if (t2.f_xy[knot(j)] != 0.0) {
              t2.f_xy[knot(j)] = 0.0;
              ++r.cross_zeroed[e];
            }
            continue;
          }
          const double need = std::abs(h * t2.f_xy[knot(j)]) / 3 * (1 + 1e-9);
          if (S(j) < need) {
            r.worst_before[e] = std::min(r.worst_before[e], S(j));
            fn[knot(j)] = sigma * need - s1d;
            raised[j] = 1;
          }
        }
      }
      if (!dipped) break;
    }
    r.knots_raised[e] = int(std::count(raised.begin(), raised.end(), 1));
  }
  if (!r.any()) return r;
  compute_safeguard(t2);
  // Measure the change on the outermost cell layer of every edge (the only cells that changed).
  const BakedTerm before = make_baked_term(original), after = make_baked_term(t2);
  for (int e = 0; e < 4; ++e) {
    if (!r.knots_raised[e] && !r.cross_zeroed[e]) continue;
    const int axis = e / 2, along = 1 - axis;
    const double w = t2.spacing(axis);
    // 24 points per cell: the Hermite extremes at 1/3 and 2/3 included.
    double lo[2], hi[2];
    lo[axis] = e % 2 ? t2.upper[axis] - w : t2.lower[axis];
    hi[axis] = lo[axis] + w;
    lo[along] = t2.lower[along];
    hi[along] = t2.upper[along];
    int grid[2];
    grid[axis] = 24;
    grid[along] = 24 * (n[along] - 1);
    max_table_change(before, after, lo, hi, grid[0], grid[1], r.max_change, r.max_grad_change);
  }
  return r;
}

}  // namespace yarnhom
