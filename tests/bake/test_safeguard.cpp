// The safeguard outside the box (spec section 8, docs/bake.md): continuity checked numerically
// from both sides of every border, third derivatives, finite energy far outside, the stored
// coefficients evaluated by the formulas of docs/bake.md alone (the outward rise of the total
// energy: test_safeguard_outward.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "bake/bake_table.hpp"
#include "bake/bake_accuracy.hpp"
#include "material/baked_eval.hpp"
#include "bake/corner_twist.hpp"
#include "material/material.hpp"
#include "bake/pair_check.hpp"
#include "cpu/network_eval.hpp"
#include "tests/common/bake_test_util.hpp"
#include "tests/common/outward_rays.hpp"

using namespace yarnhom;

namespace {

struct Case {
  const char* name;
  std::vector<double> lo, hi;
};

}  // namespace

// Value, f' and f'' continuous at both ends (C2); f''' exactly 0 outside.
TEST(Safeguard, OneDimensionalIsC2AndQuadratic) {
  for (unsigned seed : {1u, 2u, 3u}) {
    ModelNetwork net = test::random_model_network("5", {-230.0}, {230.0}, seed);
    BakedTerm t = make_baked_term(bake_network(net, 200, 100));
    const double W = 460, delta = 1e-7 * W;
    for (double X : {-230.0, 230.0}) {
      double a[4], b[4];
      const double xa = X - delta, xb = X + delta;
      eval_baked_jet(t, &xa, 3, a);
      eval_baked_jet(t, &xb, 3, b);
      // Inside side (a when X is the upper end) and outside side.
      const double* in = X > 0 ? a : b;
      const double* out = X > 0 ? b : a;
      EXPECT_NEAR(in[0], out[0], 4 * delta * std::abs(in[1]) + 1e-13 * (1 + std::abs(in[0])));
      EXPECT_NEAR(in[1], out[1], 4 * delta * std::abs(in[2]) + 1e-10 * std::abs(in[1]) + 1e-16);
      EXPECT_NEAR(in[2], out[2], 4 * delta * std::abs(in[3]) + 1e-8 * std::abs(in[2]) + 1e-18);
      EXPECT_EQ(out[3], 0.0);
    }
    for (double x : {-1e4, -500.0, -231.0, 231.0, 700.0, 1e5}) {
      double j[4];
      eval_baked_jet(t, &x, 3, j);
      EXPECT_EQ(j[3], 0.0);
      EXPECT_TRUE(std::isfinite(j[0]));
    }
  }
}

// Value and gradient continuous across the box boundary and across every border between
// sectors: points on the four lines x = lower/upper, y = lower/upper, extended a box width
// beyond the box on both sides, evaluated just on either side of the line.
TEST(Safeguard, TwoDimensionalIsC1AcrossEveryBorder) {
  const std::vector<Case> cases = {{"02", {-0.2, -0.2}, {1.0, 1.0}},
                                   {"13", {-0.7, -170.0}, {0.7, 170.0}},
                                   {"25", {-0.2, -230.0}, {1.0, 230.0}}};
  unsigned seed = 20;
  int checked = 0;
  for (const Case& c : cases) {
    ModelNetwork net = test::random_model_network(c.name, c.lo, c.hi, seed++);
    BakedTerm t = make_baked_term(bake_network(net, 200, 60));
    const double W[2] = {c.hi[0] - c.lo[0], c.hi[1] - c.lo[1]};
    for (int axis = 0; axis < 2; ++axis)
      for (double X : {c.lo[axis], c.hi[axis]}) {
        const int along = 1 - axis;
        const double delta = 1e-7 * W[axis];
        for (int k = 0; k <= 300; ++k) {
          const double y = c.lo[along] - W[along] + 3 * W[along] * (k + 0.5) / 301;
          double pa[2], pb[2];
          pa[axis] = X - delta;
          pb[axis] = X + delta;
          pa[along] = pb[along] = y;
          double a[10], b[10];
          eval_baked_jet(t, pa, 2, a);
          eval_baked_jet(t, pb, 2, b);
          EXPECT_NE(baked_sector(t, pa), baked_sector(t, pb));
          // Hessian entries d2f/ds_i ds_axis on either side bound the gradient's change.
          auto H = [&](const double* j, int i, int m) { return std::abs(j[jet_ch2(2, std::min(i, m), std::max(i, m))]); };
          const double tol0 = 4 * delta * std::max(std::abs(a[1 + axis]), std::abs(b[1 + axis])) +
                              1e-12 * (1 + std::abs(a[0]));
          EXPECT_NEAR(a[0], b[0], tol0) << c.name << " axis " << axis << " X " << X << " y " << y;
          for (int i = 0; i < 2; ++i) {
            const double tol = 4 * delta * std::max(H(a, i, axis), H(b, i, axis)) + 1e-9 * std::abs(a[1 + i]) + 1e-15;
            EXPECT_NEAR(a[1 + i], b[1 + i], tol) << c.name << " grad " << i << " axis " << axis << " X " << X << " y " << y;
          }
          ++checked;
        }
      }
  }
  EXPECT_EQ(checked, 3 * 4 * 301);
}

// Every sector is reached; a corner is the bilinear D00 + D10 dx + D01 dy + D11 dx dy (first
// order along both outward normals, C1 with both bands) and a band is first order across its
// edge, whatever the table's curvature there.
TEST(Safeguard, SectorsAndFirstOrderContinuation) {
  test::Poly p;  // f = x^2 y + 2 y^2: f_xx, f_yy, f_xxy nonzero at the corners
  p.c[2][1] = 1.0;
  p.c[0][2] = 2.0;
  BakedTerm t = make_baked_term(bake_function(term_by_name("01"), {-1, -1}, {1, 1}, {9, 9}, test::poly_function(p, 2)));
  int seen[9] = {};
  for (double x : {-2.0, 0.0, 2.0})
    for (double y : {-2.0, 0.0, 2.0}) {
      const double s[2] = {x, y};
      seen[baked_sector(t, s)]++;
    }
  for (int k = 0; k < 9; ++k) EXPECT_EQ(seen[k], 1) << "sector " << k;
  // Corner (upper, upper) at (1, 1): f = 3, f_x = 2 x y = 2, f_y = x^2 + 4 y = 5, f_xy = 2 x = 2.
  const double dx = 1.0, dy = 0.5;
  const double s[2] = {1 + dx, 1 + dy};
  double j[10];
  eval_baked_jet(t, s, 3, j);
  EXPECT_NEAR(j[0], 3 + 2 * dx + 5 * dy + 2 * dx * dy, 1e-12);
  EXPECT_NEAR(j[jet_ch2(2, 0, 0)], 0.0, 1e-12);  // no curvature along either outward normal
  EXPECT_NEAR(j[jet_ch2(2, 1, 1)], 0.0, 1e-12);
  EXPECT_NEAR(j[jet_ch2(2, 0, 1)], 2.0, 1e-12);
  for (int q = 6; q < 10; ++q) EXPECT_EQ(j[q], 0.0);  // third derivatives 0 in a corner
  // y upper band at x = 0.25: F = f(x, 1) + f_y(x, 1) dy = x^2 + 2 + (x^2 + 4) dy; d2F/dy2 = 0.
  const double b[2] = {0.25, 1.7};
  eval_baked_jet(t, b, 2, j);
  EXPECT_NEAR(j[0], 0.0625 + 2 + (0.0625 + 4) * 0.7, 1e-12);
  EXPECT_NEAR(j[jet_ch2(2, 1, 1)], 0.0, 1e-12);
}

// Far outside: finite for random networks; a 1D term whose ends rise with positive curvature
// grows on both sides.
TEST(Safeguard, FiniteAndGrowingFarOutside) {
  ModelNetwork net = test::random_model_network("23", {-0.2, -200.0}, {1.0, 200.0}, 31);
  BakedTerm t = make_baked_term(bake_network(net, 200, 50));
  for (double x : {-1e3, -5.0, 0.4, 7.0, 1e4})
    for (double y : {-1e6, -900.0, 0.0, 500.0, 1e5}) {
      BakedJet2 r = eval_baked_2d(t, {x, y});
      EXPECT_TRUE(std::isfinite(r.f) && r.g.allFinite() && r.H.allFinite()) << x << " " << y;
    }
  test::Poly p1;  // 1D: x^2 + 0.2 x^3 on [-1, 2]: f' n > 0 and f'' > 0 at both ends
  p1.c[2][0] = 1; p1.c[3][0] = 0.2;
  BakedTerm q1 = make_baked_term(bake_function(term_by_name("0"), {-1}, {2}, {50}, test::poly_function(p1, 1)));
  double lo_prev = -1e300, hi_prev = -1e300;
  for (int r = 0; r < 200; ++r) {
    const double a = -1 - 0.5 * r, b = 2 + 0.5 * r;
    const double fa = eval_baked_1d(q1, a).f, fb = eval_baked_1d(q1, b).f;
    EXPECT_GT(fa, lo_prev);
    EXPECT_GT(fb, hi_prev);
    lo_prev = fa;
    hi_prev = fb;
  }
}

// The stored coefficients, evaluated with the formulas of docs/bake.md (written out here
// independently of the evaluator), give the evaluator's values outside the box.
TEST(Safeguard, StoredCoefficientsReproduceTheExtension) {
  ModelNetwork n1 = test::random_model_network("1", {-0.7}, {0.7}, 41);
  BakedTable t1 = bake_network(n1, 200, 100);
  BakedTerm e1 = make_baked_term(t1);
  for (double x : {-3.0, -0.71, 0.75, 4.0}) {
    const auto& c = x < 0 ? t1.safeguard_lower : t1.safeguard_upper;
    EXPECT_NEAR(eval_baked_1d(e1, x).f, c[0] * x * x + c[1] * x + c[2], 1e-10 * (1 + std::abs(c[2])));
  }
  ModelNetwork n2 = test::random_model_network("15", {-0.7, -200.0}, {0.7, 200.0}, 42);
  BakedTable t2 = bake_network(n2, 200, 40);
  BakedTerm e2 = make_baked_term(t2);
  // Edge x_upper at a knot y_j: F = g0 + g1 t + g2 t^2/2, t = x - upper_x.
  const int j = 17;
  const double y = knot_position(-200, 200, 40, j), tt = 0.3;
  const double* g = t2.edges[1].data() + 6 * j;
  EXPECT_NEAR(eval_baked_2d(e2, {0.7 + tt, y}).f, g[0] + g[2] * tt + 0.5 * g[4] * tt * tt, 1e-10 * (1 + std::abs(g[0])));
  // Its derivative along the edge: g0' + g1' t + g2' t^2/2.
  EXPECT_NEAR(eval_baked_2d(e2, {0.7 + tt, y}).g[1], g[1] + g[3] * tt + 0.5 * g[5] * tt * tt, 1e-8 * (1 + std::abs(g[1])));
  // Between edge knots each g_k is the cubic Hermite interpolant of (g_k, g_k') (docs/bake.md):
  // evaluated from the stored columns alone, at a third of the way from knot j to j + 1.
  {
    const double hy = 400.0 / 39, v = 1.0 / 3;
    const double H00 = 1 - 3 * v * v + 2 * v * v * v, H10 = v - 2 * v * v + v * v * v, H01 = 3 * v * v - 2 * v * v * v,
                 H11 = v * v * v - v * v;
    const double* g1 = t2.edges[1].data() + 6 * (j + 1);
    double gk[3];
    for (int k = 0; k < 3; ++k)
      gk[k] = H00 * g[2 * k] + hy * H10 * g[2 * k + 1] + H01 * g1[2 * k] + hy * H11 * g1[2 * k + 1];
    const double ref = gk[0] + gk[1] * tt + 0.5 * gk[2] * tt * tt;
    EXPECT_NEAR(eval_baked_2d(e2, {0.7 + tt, y + v * hy}).f, ref, 1e-10 * (1 + std::abs(ref)));
  }
  // Corner (lower, upper): x below, y above.
  const auto& a = t2.corners[2];
  const double dx = -0.4, dy = 55;
  const double ref = a[0] + a[1] * dx + a[2] * dy + 0.5 * a[3] * dx * dx + a[4] * dx * dy + 0.5 * a[5] * dy * dy +
                     0.5 * a[6] * dx * dx * dy + 0.5 * a[7] * dx * dy * dy;
  EXPECT_NEAR(eval_baked_2d(e2, {-0.7 + dx, 200 + dy}).f, ref, 1e-10 * (1 + std::abs(ref)));
}

// A tampered coefficient is refused, with the file and the table named.
TEST(Safeguard, TamperedCoefficientsRefused) {
  ModelNetwork n = test::random_model_network("02", {-0.2, -0.2}, {1.0, 1.0}, 43);
  BakedTable t = bake_network(n, 200, 20);
  t.corners[3][0] *= 1.001;
  try {
    make_baked_term(t, "run/baked.h5");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("run/baked.h5"), std::string::npos) << m;
    EXPECT_NE(m.find("/tables/02"), std::string::npos) << m;
    EXPECT_NE(m.find("corner_upper_upper"), std::string::npos) << m;
  }
}

// A diverging simulation may pass NaN or infinite strains: the result is NaN or infinite, never
// a crash or a read out of the table.
TEST(Safeguard, NonFiniteStrainsGiveNonFiniteResults) {
  ModelNetwork n2 = test::random_model_network("02", {-0.2, -0.2}, {1.0, 1.0}, 44);
  BakedTerm t2 = make_baked_term(bake_network(n2, 200, 20));
  ModelNetwork n1 = test::random_model_network("0", {-0.2}, {1.0}, 45);
  BakedTerm t1 = make_baked_term(bake_network(n1, 50, 20));
  const double nan = std::nan(""), inf = INFINITY;
  EXPECT_TRUE(std::isnan(eval_baked_2d(t2, {nan, 0.3}).f));
  EXPECT_TRUE(std::isnan(eval_baked_2d(t2, {0.3, nan}).g[1]));
  EXPECT_FALSE(std::isfinite(eval_baked_2d(t2, {inf, 0.3}).f));
  EXPECT_TRUE(std::isnan(eval_baked_1d(t1, nan).f));
  EXPECT_FALSE(std::isfinite(eval_baked_1d(t1, -inf).f));
}
