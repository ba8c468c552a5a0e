// The metrics: quadratic expansion error (zero for quadratics, the hand-computed value for
// cubics), Eq. 4's combination, fit error, bake deviation.
#include <gtest/gtest.h>

#include <cmath>

#include "bake/bake_accuracy.hpp"
#include "bake/bake_table.hpp"
#include "bake/fit_error.hpp"
#include "bake/quadratic_error.hpp"
#include "tests/bake/bake_test_util.hpp"

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
  auto ref = network_function(net);
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
