// The edge slope repair (bake/edge_slope_repair.hpp): where a pair's total falls outward at an
// edge of its box, the 2D table's outward derivative at that edge's knots is raised so that the
// total's outward slope is >= 0 along the whole edge; nothing else changes: no knot value, no
// interior knot, no cell beyond the outermost layer; a second repair finds nothing to do.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "bake/bake_table.hpp"
#include "material/baked_eval.hpp"
#include "bake/edge_slope_repair.hpp"
#include "bake/pair_check.hpp"
#include "tests/common/bake_test_util.hpp"

using namespace yarnhom;

namespace {

// Psi_I = x^2 on [-1, 1], Psi_J = y^2 / 4 on [-2, 2], Psi_IJ = -2 x y^2 (zero on both axes,
// like an axis-projected residual; degree <= 3 per variable, so the bicubic table is exact).
// The total's outward slope: x upper 2 - 2 y^2 (falls for |y| > 1), x lower 2 + 2 y^2 (rises),
// y upper and y lower both 1 - 8 x (falls for x > 1/8).
struct Fixture {
  BakedTable ti, tj, t2;
  Fixture() {
    test::Poly pi, pj, p2;
    pi.c[2][0] = 1.0;
    pj.c[2][0] = 0.25;
    p2.c[1][2] = -2.0;
    ti = bake_function(term_by_name("0"), {-1}, {1}, {41}, test::poly_function(pi, 1));
    tj = bake_function(term_by_name("2"), {-2}, {2}, {41}, test::poly_function(pj, 1));
    t2 = bake_function(term_by_name("02"), {-1, -2}, {1, 2}, {11, 21}, test::poly_function(p2, 2));
  }
};

// The total's outward slope at the boundary point `along` of edge e.
double edge_slope(const BakedTerm& t2, const BakedTerm& ti, const BakedTerm& tj, int e, double along) {
  const int axis = e / 2;
  const double sigma = e % 2 ? 1 : -1;
  double s[2];
  s[axis] = e % 2 ? t2.hi[axis] : t2.lo[axis];
  s[1 - axis] = along;
  double jet[3];
  eval_baked_jet(t2, s, 1, jet);
  const double one = axis == 0 ? eval_baked_1d(ti, s[0]).df : eval_baked_1d(tj, s[1]).df;
  return sigma * (jet[1 + axis] + one);
}

}  // namespace

TEST(EdgeSlopeRepair, RaisesTheFallingEdgesOnlyAndOnlyInTheirOuterCells) {
  Fixture f;
  const BakedTable original = f.t2;
  const BakedTerm ti = make_baked_term(f.ti), tj = make_baked_term(f.tj);
  const PairCheck before = check_pair(make_baked_term(original), &ti, &tj);
  EXPECT_EQ(before.falling[0], 0);
  for (int e : {1, 2, 3}) EXPECT_GT(before.falling[e], 0) << e;

  const EdgeSlopeRepair r = repair_edge_slopes(f.t2, &ti, &tj);
  ASSERT_TRUE(r.any());
  EXPECT_EQ(r.knots_raised[0], 0);
  EXPECT_EQ(r.cross_zeroed[0], 0);
  // x upper: knots with |y| > 1 (y = -2 .. -1.2 and 1.2 .. 2 at spacing 0.2: 10), slope down to -6.
  EXPECT_EQ(r.knots_raised[1], 10);
  EXPECT_NEAR(r.worst_before[1], -6.0, 1e-9);
  EXPECT_GT(r.knots_raised[2], 0);
  EXPECT_GT(r.knots_raised[3], 0);
  EXPECT_NE(r.summary().find("edge slope repair"), std::string::npos) << r.summary();

  const BakedTerm t2 = make_baked_term(f.t2);
  // 1. The total's outward slope is >= 0 along every edge, between knots too.
  for (int e = 0; e < 4; ++e) {
    const int along = 1 - e / 2;
    for (int k = 0; k <= 400; ++k) {
      const double a = t2.lo[along] + (t2.hi[along] - t2.lo[along]) * k / 400;
      EXPECT_GE(edge_slope(t2, ti, tj, e, a), -1e-12) << "edge " << e << " at " << a;
    }
  }
  const PairCheck after = check_pair(t2, &ti, &tj);
  for (int e = 0; e < 4; ++e) EXPECT_EQ(after.falling[e], 0) << after.summary();
  // 2. Knot values never change; interior knots not at all; the x lower edge not at all.
  const int n0 = 11, n1 = 21;
  for (int i = 0; i < n0; ++i)
    for (int j = 0; j < n1; ++j) {
      const size_t q = size_t(i) * n1 + j;
      EXPECT_EQ(f.t2.f[q], original.f[q]);
      const bool boundary = i == n0 - 1 || j == 0 || j == n1 - 1;  // the three repaired edges
      if (!boundary) {
        EXPECT_EQ(f.t2.f_x[q], original.f_x[q]) << i << "," << j;
        EXPECT_EQ(f.t2.f_y[q], original.f_y[q]) << i << "," << j;
        EXPECT_EQ(f.t2.f_xy[q], original.f_xy[q]) << i << "," << j;
      }
    }
  // 3. Beyond the outermost cell layer the table is the original exactly; in it, the change is
  //    within what the changed knot derivatives can do (|d f_n| h (4/27) + |d f_xy| h_x h_y (4/27)^2
  //    per knot, two knots per cell edge), and the report's measure is that change.
  const BakedTerm t0 = make_baked_term(original);
  const double hx = f.t2.spacing(0), hy = f.t2.spacing(1);
  double dfn = 0, dfxy = 0, seen = 0;
  for (size_t q = 0; q < f.t2.f.size(); ++q) {
    dfn = std::max({dfn, std::abs(f.t2.f_x[q] - original.f_x[q]), std::abs(f.t2.f_y[q] - original.f_y[q])});
    dfxy = std::max(dfxy, std::abs(f.t2.f_xy[q] - original.f_xy[q]));
  }
  for (int a = 0; a <= 100; ++a)
    for (int b = 0; b <= 200; ++b) {
      const double s[2] = {-1 + 2.0 * a / 100, -2 + 4.0 * b / 200};
      double p[3], q[3];
      eval_baked_jet(t0, s, 1, p);
      eval_baked_jet(t2, s, 1, q);
      const double margin = 1e-9;  // points on the layer's inner knot line may fall in either cell
      const bool outer = s[0] > 1 - hx - margin || s[1] < -2 + hy + margin || s[1] > 2 - hy - margin;
      if (!outer) {
        EXPECT_EQ(p[0], q[0]) << s[0] << "," << s[1];
        EXPECT_EQ(p[1], q[1]) << s[0] << "," << s[1];
        EXPECT_EQ(p[2], q[2]) << s[0] << "," << s[1];
      }
      seen = std::max(seen, std::abs(q[0] - p[0]));
    }
  EXPECT_GT(seen, 0.0);
  EXPECT_LE(seen, 2 * (dfn * std::max(hx, hy) * 4 / 27 + dfxy * hx * hy * 16 / 729) + 1e-12);
  EXPECT_GE(r.max_change, 0.97 * seen);  // the report samples 24 points per cell
  // 4. The axis projection survives: the table is still 0 on both axes.
  for (int k = 0; k <= 100; ++k) {
    EXPECT_NEAR(eval_baked_2d(t2, {-1 + 2.0 * k / 100, 0.0}).f, 0.0, 1e-12);
    EXPECT_NEAR(eval_baked_2d(t2, {0.0, -2 + 4.0 * k / 100}).f, 0.0, 1e-12);
  }
  // 5. A second repair finds nothing to do.
  BakedTable again = f.t2;
  EXPECT_FALSE(repair_edge_slopes(again, &ti, &tj).any());
  EXPECT_EQ(again.f_x, f.t2.f_x);
  EXPECT_EQ(again.f_xy, f.t2.f_xy);
}

// A dip between two knots that are themselves fine (a large cross derivative) is caught too; a
// table with HYLC's linear extrapolation is never touched.
TEST(EdgeSlopeRepair, CatchesDipsBetweenKnotsAndLeavesLinearTablesAlone) {
  Fixture f;
  const BakedTerm ti = make_baked_term(f.ti), tj = make_baked_term(f.tj);
  BakedTable t = f.t2;
  // x lower edge: S = -(f_x - 2) = 2 + 2 y^2 >= 2 at the knots; a cross derivative of 150 at
  // the knot y = 0 swings the cubic of the neighbouring cells well below 0.
  const int n1 = 21, j0 = 10;
  t.f_xy[j0] = 150.0;
  compute_safeguard(t);
  double lowest = 1e300;
  {
    const BakedTerm b = make_baked_term(t);
    for (int k = 0; k <= 400; ++k) lowest = std::min(lowest, edge_slope(b, ti, tj, 0, -2 + 4.0 * k / 400));
  }
  ASSERT_LT(lowest, -0.5);
  BakedTable lin = t;
  lin.extrapolation = kBakedLinear;
  EXPECT_FALSE(repair_edge_slopes(lin, &ti, &tj).any());
  const EdgeSlopeRepair r = repair_edge_slopes(t, &ti, &tj);
  EXPECT_EQ(r.knots_raised[0], 0);
  EXPECT_GE(r.cross_zeroed[0], 1);
  EXPECT_EQ(t.f_xy[j0], 0.0);
  const BakedTerm a = make_baked_term(t);
  for (int k = 0; k <= 400; ++k) EXPECT_GE(edge_slope(a, ti, tj, 0, -2 + 4.0 * k / 400), -1e-12) << k;
  (void)n1;
}

// A dip confined between the last of a grid of samples and a knot: S = 20 and 0.001 at two knots
// of the x lower edge, the second's slope along the edge pointing down into the cell (S just
// before it about 0.001 - 1 u + 60 u^2, u the distance to the knot in cells: -0.003 at u = 1/120).
// The repair finds it from the cubic's stationary points.
TEST(EdgeSlopeRepair, CatchesADipNextToAKnot) {
  Fixture f;
  const BakedTerm ti = make_baked_term(f.ti), tj = make_baked_term(f.tj);
  BakedTable t = f.t2;
  const int j = 10;       // y = 0; the cell [0, 0.2] (knot spacing h = 0.2)
  t.f_x[j] = 2 - 20.0;    // S = -(f_x + Psi_I'(-1)) = -(f_x - 2)
  t.f_x[j + 1] = 2 - 0.001;
  t.f_xy[j] = 0;
  t.f_xy[j + 1] = -5.0;   // slope of S along the edge per cell: sigma h f_xy = 1
  compute_safeguard(t);
  auto lowest_in_cell = [&](const BakedTable& tb) {
    const BakedTerm b = make_baked_term(tb);
    double lo = 1e300;
    for (int k = 0; k <= 4000; ++k) lo = std::min(lo, edge_slope(b, ti, tj, 0, 0.2 * k / 4000));
    return lo;
  };
  ASSERT_LT(lowest_in_cell(t), -2e-3);
  const EdgeSlopeRepair r = repair_edge_slopes(t, &ti, &tj);
  EXPECT_GE(r.cross_zeroed[0], 1);
  EXPECT_GE(lowest_in_cell(t), -1e-12);
}
