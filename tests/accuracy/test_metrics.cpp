// The metrics: quadratic expansion error (zero for quadratics, the hand-computed value for
// cubics), Eq. 4's combination, fit error, bake deviation.
#include <gtest/gtest.h>

#include <cmath>

#include "bake/bake_accuracy.hpp"
#include "bake/bake_table.hpp"
#include "accuracy/fit_error.hpp"
#include "accuracy/quadratic_error.hpp"
#include "tests/common/bake_test_util.hpp"

using namespace yarnhom;

TEST(QuadraticError, ZeroForQuadratics) {
  test::Poly q1;
  q1.c[0][0] = 3; q1.c[1][0] = -2; q1.c[2][0] = 5;
  EXPECT_LT(quadratic_expansion_error(test::poly_function(q1, 1), 1, {-0.1, 0.3, 0.9}, {0.012}), 1e-14);
  test::Poly q2;
  q2.c[0][0] = 1; q2.c[1][0] = 2; q2.c[0][1] = -1; q2.c[2][0] = 4; q2.c[1][1] = -3; q2.c[0][2] = 0.5;
  EXPECT_LT(quadratic_expansion_error(test::poly_function(q2, 2), 2, {0.1, 0.2, -0.5, 0.7}, {0.012, 0.014}), 1e-14);
}

// f = c x^3: f - T2 = c delta^3 exactly. Over the N midpoints delta_k = ((k + 1/2)/N - 1/2) w,
// mean |delta^3| = (w/N)^3 (2/N) sum_{j<N/2} (j + 1/2)^3 and sum_{j<M} (j + 1/2)^3 = M^2 (2M^2 - 1)/8,
// so D = |c| w^3 (1/32 - 1/(16 N^2)) at every point.
TEST(QuadraticError, HandComputedForCubic1D) {
  test::Poly p;
  p.c[3][0] = -2.5;
  p.c[2][0] = 7;  // quadratic parts do not matter
  const double w = 0.012, N = 1024;
  const double expect = 2.5 * w * w * w * (1.0 / 32 - 1.0 / (16 * N * N));
  auto D = expansion_error_per_point(test::poly_function(p, 1), 1, {-0.2, 0.0, 0.55, 1.0}, {w});
  // |f - T2| ~ 1e-7 is the difference of numbers ~ 1: rounding ~ 1e-15 each, ~1e-8 relative.
  for (double x : D) EXPECT_NEAR(x, expect, 1e-7 * expect);
}

// f = x^2 y: f - T2 = dx^2 dy; on the 32 x 32 midpoint grid the mean of dx^2 |dy| separates:
// mean dx^2 = wx^2 (N^2 - 1) / (12 N^2), mean |dy| = wy / 4.
TEST(QuadraticError, HandComputedForCubic2D) {
  test::Poly p;
  p.c[2][1] = 1.0;
  p.c[1][1] = 3.0;
  const double wx = 0.012, wy = 4.0, N = 32;
  const double expect = wx * wx * (N * N - 1) / (12 * N * N) * wy / 4;
  auto D = expansion_error_per_point(test::poly_function(p, 2), 2, {0.3, -150.0, -0.1, 20.0}, {wx, wy});
  for (double x : D) EXPECT_NEAR(x, expect, 1e-7 * expect);
}

TEST(QuadraticError, CombinesAsEquation4) {
  std::map<std::string, double> e = {{"0", 1.0}, {"1", 3.0}, {"02", 10.0}, {"13", 20.0}, {"25", 30.0}};
  EXPECT_DOUBLE_EQ(combine_expansion_errors(e), 2.0 + 20.0);
  EXPECT_THROW(expansion_error_per_point(test::poly_function(test::Poly{}, 2), 2, {0, 0}, {1, 1}, 1000), std::invalid_argument);
}

TEST(FitError, KnownResiduals) {
  test::Poly p;  // f = x^2, exact gradient 2x
  p.c[2][0] = 1;
  TermData data;
  data.term = term_by_name("0");
  data.n = 4;
  data.strain = {0, 1, 2, 3};
  data.energy = {0.5, 1, 4, 9};          // residuals -0.5, 0, 0, 0
  data.gradient = {0, 2, 4, 7};          // gradient residual 1 at the last point
  FitError e = fit_error(test::poly_function(p, 1), data);
  EXPECT_DOUBLE_EQ(e.energy_mae, 0.125);
  EXPECT_DOUBLE_EQ(e.energy_max, 0.5);
  EXPECT_NEAR(e.energy_rmse, 0.25, 1e-15);
  EXPECT_DOUBLE_EQ(e.grad_mae, 0.25);
  EXPECT_NEAR(e.grad_rel, 0.25 / 3.25, 1e-15);
}

// The deviation of a baked network falls with resolution as the h^4 of Hermite interpolation.
TEST(BakeDeviation, FallsWithResolution) {
  ModelNetwork net = test::random_model_network("02", {-0.2, -0.2}, {1.0, 1.0}, 61);
  auto ref = material_function(net);  // what bake bakes
  double prev = 1e300;
  for (int res : {13, 25, 49}) {
    BakedTerm t = make_baked_term(bake_network(net, 200, res, nullptr, false));  // interpolation alone
    BakeDeviation d = bake_deviation(ref, baked_function(t), 2, net.lower, net.upper, 101);
    EXPECT_GT(d.range, 0);
    EXPECT_LE(d.mean_rel, d.max_rel);
    EXPECT_LT(d.max_rel, prev / 8) << res;
    prev = d.max_rel;
  }
}

// The axis projection of a 2D term (bake/term_function.hpp): 0 with its gradient along both
// axes (to rounding), every mixed derivative the network's, the identity on a function that
// already vanishes on the axes, and its jet the derivatives of its value (central differences).
TEST(AxisProjection, VanishesOnTheAxesAndKeepsTheMixedDerivatives) {
  const ModelNetwork net = test::random_model_network("02", {-0.2, -0.3}, {1.0, 0.8}, 62);
  const TermFunction N = network_function(net), R = material_function(net);
  const std::vector<double> pts = {0.37, 0.0, 0.0, -0.21, 0.0, 0.0, -0.15, 0.0, 0.0, 0.55, 0.4, -0.25};
  const int n = 6;
  const std::vector<double> r = R(pts.data(), n, 3), nn = N(pts.data(), n, 3);
  double scale = 0;
  for (double v : nn) scale = std::max(scale, std::abs(v));
  const double tol = 1e-14 * scale;
  for (int p = 0; p < 4; ++p) {
    EXPECT_NEAR(r[p], 0.0, tol) << p;  // value on an axis
    if (pts[2 * p + 1] == 0) {
      EXPECT_NEAR(r[size_t(1) * n + p], 0.0, tol) << p;  // d/dx along the x axis
      EXPECT_NEAR(r[size_t(3) * n + p], 0.0, tol) << p;  // d2/dx2 along it
    }
    if (pts[2 * p] == 0) {
      EXPECT_NEAR(r[size_t(2) * n + p], 0.0, tol) << p;  // d/dy along the y axis
    }
  }
  // The network is not 0 there: the projection did something.
  EXPECT_GT(std::abs(nn[0]) + std::abs(nn[size_t(1) * n]), 1e-6 * scale);
  // Mixed derivatives (channels 4 f_xy, 7 f_xxy, 8 f_xyy) are the network's everywhere.
  for (int c : {4, 7, 8})
    for (int p = 0; p < n; ++p)
      EXPECT_NEAR(r[size_t(c) * n + p], nn[size_t(c) * n + p], 1e-12 * (1 + std::abs(nn[size_t(c) * n + p])));
  // The jet is the derivative of the value, off the axes.
  const double x = 0.55, y = 0.4, h = 1e-5;
  auto at = [&](double u, double v, int order) {
    const double s[2] = {u, v};
    return R(s, 1, order);
  };
  const std::vector<double> j = at(x, y, 2);
  EXPECT_NEAR(j[1], (at(x + h, y, 0)[0] - at(x - h, y, 0)[0]) / (2 * h), 1e-7 * (1 + std::abs(j[1])));
  EXPECT_NEAR(j[2], (at(x, y + h, 0)[0] - at(x, y - h, 0)[0]) / (2 * h), 1e-7 * (1 + std::abs(j[2])));
  EXPECT_NEAR(j[3], (at(x + h, y, 1)[1] - at(x - h, y, 1)[1]) / (2 * h), 1e-6 * (1 + std::abs(j[3])));
  EXPECT_NEAR(j[5], (at(x, y + h, 1)[2] - at(x, y - h, 1)[2]) / (2 * h), 1e-6 * (1 + std::abs(j[5])));
  // Identity on x y (1 + x), which vanishes on both axes.
  test::Poly q;
  q.c[1][1] = 1;
  q.c[2][1] = 1;
  const TermFunction Q = test::poly_function(q, 2), PQ = axis_projection(Q, 2);
  const std::vector<double> a = Q(pts.data(), n, 3), b = PQ(pts.data(), n, 3);
  for (size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], 1e-15) << k;
  // A box without the origin keeps the network.
  const ModelNetwork off = test::random_model_network("02", {0.1, -0.3}, {1.0, 0.8}, 63);
  const double s[2] = {0.5, 0.0};
  EXPECT_EQ(material_function(off)(s, 1, 0)[0], network_function(off)(s, 1, 0)[0]);
}
