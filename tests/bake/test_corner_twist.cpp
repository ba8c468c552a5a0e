// The corner twist repair (bake/corner_twist.hpp): a 2D table whose outward corner twist is more
// negative than the 1D curvatures allow gets that one corner knot's f_xy raised to
// -0.9 sqrt(K_I K_J); nothing else in the table changes, the change stays in the corner cell
// and within its bound, and beyond the corner the total is a convex quadratic.
#include <gtest/gtest.h>

#include <cmath>

#include "bake/bake_table.hpp"
#include "material/baked_eval.hpp"
#include "bake/corner_twist.hpp"
#include "bake/pair_check.hpp"
#include "tests/common/bake_test_util.hpp"

using namespace yarnhom;

namespace {

// Psi_I = a x^2 / 2 on [-1, 1], Psi_J = b y^2 / 2 on [-2, 2], Psi_IJ = w x y + 0.05 x^2 y
// (degree <= 3 in each variable: the bicubic table is exact).
struct Fixture {
  BakedTable ti, tj, t2;
  Fixture(double a, double b, double w) {
    test::Poly pi, pj, p2;
    pi.c[2][0] = a / 2;
    pj.c[2][0] = b / 2;
    p2.c[1][1] = w;
    p2.c[2][1] = 0.05;
    ti = bake_function(term_by_name("0"), {-1}, {1}, {41}, test::poly_function(pi, 1));
    tj = bake_function(term_by_name("2"), {-2}, {2}, {41}, test::poly_function(pj, 1));
    t2 = bake_function(term_by_name("02"), {-1, -2}, {1, 2}, {11, 21}, test::poly_function(p2, 2));
  }
};

}  // namespace

// Outward twist at corner (sx, sy) of w x y + 0.05 x^2 y: sx sy (w + 0.1 x) at x = sx.
TEST(CornerTwist, RaisesOnlyTheCornersThatBendTheTotalDown) {
  const double a = 2.0, b = 0.5, w = 3.0;  // sqrt(a b) = 1
  Fixture f(a, b, w);
  const BakedTable original = f.t2;
  const BakedTerm ti = make_baked_term(f.ti), tj = make_baked_term(f.tj);
  const PairCheck before = check_pair(make_baked_term(original), &ti, &tj);
  const CornerTwistRepair r = repair_corner_twists(f.t2, &ti, &tj);
  const int n0 = 11, n1 = 21;
  for (int c = 0; c < 4; ++c) {
    const double sx = c & 1 ? 1 : -1, sy = c & 2 ? 1 : -1;
    const double T = sx * sy * (w + 0.1 * sx);
    EXPECT_NEAR(r.twist_before[c], T, 1e-9) << c;
    EXPECT_NEAR(r.k_first[c], a, 1e-9);
    EXPECT_NEAR(r.k_second[c], b, 1e-9);
    // Corners with sx sy < 0 have T = -(3 +- 0.1) < -0.9: repaired to exactly -0.9; the others
    // (T > 0, rising along every quadrant direction) are left alone.
    EXPECT_EQ(r.repaired[c], sx * sy < 0) << c;
    EXPECT_EQ(before.corner_bends[c], sx * sy < 0) << c;
    EXPECT_NEAR(r.twist_after[c], sx * sy < 0 ? -0.9 * std::sqrt(a * b) : T, 1e-12) << c;
  }
  // Every knot value except the repaired corners' f_xy is bit for bit the original.
  for (int i = 0; i < n0; ++i)
    for (int j = 0; j < n1; ++j) {
      const size_t k = size_t(i) * n1 + j;
      EXPECT_EQ(f.t2.f[k], original.f[k]);
      EXPECT_EQ(f.t2.f_x[k], original.f_x[k]);
      EXPECT_EQ(f.t2.f_y[k], original.f_y[k]);
      const bool corner = (i == 0 || i == n0 - 1) && (j == 0 || j == n1 - 1);
      const int c = (i == n0 - 1 ? 1 : 0) + (j == n1 - 1 ? 2 : 0);
      if (!corner || !r.repaired[c]) { EXPECT_EQ(f.t2.f_xy[k], original.f_xy[k]) << i << " " << j; }
      else { EXPECT_NE(f.t2.f_xy[k], original.f_xy[k]); }
    }
  // Inside the box the table differs only in the repaired corner cells, by at most
  // |dT| h_x h_y (4/27)^2 (the reported change is the measured one, within that bound).
  const BakedTerm o = make_baked_term(original), n = make_baked_term(f.t2);
  const double hx = 0.2, hy = 0.2, bound = (3.1 - 0.9) * hx * hy * (4.0 / 27) * (4.0 / 27);
  double worst = 0;
  for (int i = 0; i <= 100; ++i)
    for (int j = 0; j <= 200; ++j) {
      const double x = -1 + 0.02 * i, y = -2 + 0.02 * j;
      const double d = std::abs(eval_baked_2d(n, {x, y}).f - eval_baked_2d(o, {x, y}).f);
      const bool in_repaired_cell = ((x < -1 + hx && y > 2 - hy) || (x > 1 - hx && y < -2 + hy));
      if (!in_repaired_cell) {
        EXPECT_LE(d, 1e-14) << x << " " << y;
      }
      worst = std::max(worst, d);
    }
  EXPECT_GT(worst, 0.1 * bound);
  EXPECT_LE(worst, bound * (1 + 1e-9));
  EXPECT_LE(r.max_change, bound * (1 + 1e-9));
  EXPECT_GE(r.max_change, 0.95 * worst);  // measured on a 9 x 9 sample of the cell, this on 11 x 11
  // After the repair nothing bends, and the safeguard coefficients are those of the new knots
  // (make_baked_term checks them against the knots and throws otherwise).
  const PairCheck after = check_pair(n, &ti, &tj);
  for (int c = 0; c < 4; ++c) EXPECT_FALSE(after.corner_bends[c]);
  EXPECT_NE(r.summary().find("lower_upper twist"), std::string::npos) << r.summary();
}

// Far beyond a repaired corner the total is a positive definite quadratic: along every direction
// of the corner's quadrant its slope never decreases, ends positive, and the total ends far
// above its corner value; before the repair, along the worst diagonal, it fell without bound.
TEST(CornerTwist, TotalIsBoundedBelowFarOutside) {
  const double a = 2.0, b = 0.5, w = 3.0;
  Fixture f(a, b, w);
  const BakedTerm ti = make_baked_term(f.ti), tj = make_baked_term(f.tj), o = make_baked_term(f.t2);
  repair_corner_twists(f.t2, &ti, &tj);
  const BakedTerm n = make_baked_term(f.t2);
  auto total = [&](const BakedTerm& t, double x, double y) {
    return eval_baked_2d(t, {x, y}).f + eval_baked_1d(ti, x).f + eval_baked_1d(tj, y).f;
  };
  // Corner (x upper, y lower): outward quadrant (+, -).
  const double X = 1, Y = -2, corner = total(n, X, Y);
  for (int k = 0; k <= 20; ++k) {
    const double ang = 0.5 * M_PI * k / 20, c = std::cos(ang), s = std::sin(ang);
    double prev = 0, slope = -1e300;
    for (int m = 0; m <= 100; ++m) {
      const double t = 1000.0 * m / 100;
      const double v = total(n, X + t * c, Y - t * s);
      if (m > 0) {
        EXPECT_GE(v - prev, slope - 1e-9 * std::abs(slope)) << ang << " " << t;  // convex along the ray
        slope = v - prev;
      }
      prev = v;
    }
    EXPECT_GT(slope, 0) << ang;
    EXPECT_GT(prev, corner + 1e3) << ang;
  }
  // The unrepaired table along c/s = sqrt(b/a) (the diagonal where the twist wins) goes to -inf.
  const double c = std::sqrt(b / a) / std::hypot(std::sqrt(b / a), 1.0), s = 1 / std::hypot(std::sqrt(b / a), 1.0);
  EXPECT_LT(total(o, X + 1000 * c, Y - 1000 * s), -1e5);
}

// Linear tables (fit-splines, HYLC's convention) and tables without a twist problem are left
// bit for bit; a missing 1D term counts as zero curvature (twist raised to 0).
TEST(CornerTwist, LinearTablesAndMissingOneDimensionalTerms) {
  Fixture f(2.0, 0.5, 3.0);
  const BakedTerm ti = make_baked_term(f.ti);
  BakedTable lin = f.t2;
  lin.extrapolation = kBakedLinear;
  compute_safeguard(lin);
  const BakedTable lin0 = lin;
  EXPECT_FALSE(repair_corner_twists(lin, &ti, nullptr).any());
  EXPECT_EQ(lin.f_xy, lin0.f_xy);
  const CornerTwistRepair r = repair_corner_twists(f.t2, &ti, nullptr);
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(r.k_second[c], 0.0);
    if (r.repaired[c]) { EXPECT_EQ(r.twist_after[c], 0.0); }
  }
  EXPECT_TRUE(r.any());
  Fixture g(2.0, 0.5, 0.5);  // |T| <= 0.6 < 0.9: nothing to do
  const BakedTable g0 = g.t2;
  const BakedTerm gi = make_baked_term(g.ti), gj = make_baked_term(g.tj);
  EXPECT_FALSE(repair_corner_twists(g.t2, &gi, &gj).any());
  EXPECT_EQ(g.t2.f_xy, g0.f_xy);
}
