// Baked tables against the network they come from: exact at the knots, within the Hermite
// interpolation error between them (a bound in 1D, the h^4 convergence rate in 2D). These bake
// without the 1D end repair (bake/boundary_repair.hpp), which changes a random 1D network's
// outer 5 % on purpose (2D tables are never changed): here the subject is the interpolation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "bake/bake_table.hpp"
#include "material/baked_eval.hpp"
#include "cpu/network_eval.hpp"
#include "tests/common/bake_test_util.hpp"

using namespace yarnhom;

namespace {

double rel(double a, double b) { return std::abs(a - b) / (std::abs(b) + 1e-300); }

}  // namespace

TEST(BakeTable, KnotsReproduceNetwork1D) {
  ModelNetwork net = test::random_model_network("3", {-200.0}, {170.0}, 11);
  BakedTable tb = bake_network(net, 200, 100, nullptr, false);
  BakedTerm t = make_baked_term(tb);
  double max_f = 0, max_g = 0;
  for (int i = 0; i < 200; ++i) {
    const double x = knot_position(-200, 170, 200, i);
    auto ref = cpu::eval_network_physical(net, &x, 1, 1);
    BakedJet1 j = eval_baked_1d(t, x);
    max_f = std::max(max_f, std::abs(j.f - ref[0]) / (std::abs(ref[0]) + 1));
    max_g = std::max(max_g, rel(j.df, ref[1]));
  }
  EXPECT_LT(max_f, 1e-13);
  EXPECT_LT(max_g, 1e-10);
}

TEST(BakeTable, KnotsReproduceNetwork2D) {
  ModelNetwork net = test::random_model_network("03", {-0.2, -150.0}, {1.0, 150.0}, 12);
  BakedTable tb = bake_network(net, 200, 30, nullptr, false);
  BakedTerm t = make_baked_term(tb);
  for (int i = 0; i < 30; i += 3)
    for (int j = 0; j < 30; j += 4) {
      const double s[2] = {knot_position(-0.2, 1.0, 30, i), knot_position(-150, 150, 30, j)};
      auto ref = material_function(net)(s, 1, 2);  // a 2D term: the network's axis projection
      double jet[10];
      eval_baked_jet(t, s, 2, jet);
      EXPECT_NEAR(jet[0], ref[0], 1e-13 * (std::abs(ref[0]) + 1));
      EXPECT_NEAR(jet[1], ref[1], 1e-10 * std::abs(ref[1]) + 1e-14);
      EXPECT_NEAR(jet[2], ref[2], 1e-10 * std::abs(ref[2]) + 1e-14);
      // f_xy is stored; the bicubic reproduces it at the knots.
      EXPECT_NEAR(jet[4], ref[4], 1e-9 * std::abs(ref[4]) + 1e-14);
    }
}

// Between knots: |f - p| <= h^4/384 max|f''''| for cubic Hermite interpolation. f'''' is
// estimated by central differences of the exact third derivative on a fine grid.
TEST(BakeTable, BetweenKnotsWithinHermiteBound1D) {
  ModelNetwork net = test::random_model_network("0", {-0.2}, {1.0}, 13);
  for (int res : {20, 50, 200}) {
    BakedTerm t = make_baked_term(bake_network(net, res, 10, nullptr, false));
    const int N = 4001;
    std::vector<double> xs(N);
    for (int i = 0; i < N; ++i) xs[i] = -0.2 + 1.2 * i / (N - 1);
    auto ref = cpu::eval_network_physical(net, xs.data(), N, 3);
    double f4 = 0, err = 0;
    for (int i = 1; i < N; ++i) f4 = std::max(f4, std::abs(ref[3 * N + i] - ref[3 * N + i - 1]) / (xs[i] - xs[i - 1]));
    for (int i = 0; i < N; ++i) err = std::max(err, std::abs(eval_baked_1d(t, xs[i]).f - ref[i]));
    const double h = 1.2 / (res - 1);
    const double bound = std::pow(h, 4) / 384.0 * f4;
    EXPECT_LE(err, 1.1 * bound + 1e-14) << "res " << res;
    EXPECT_GT(err, 0.01 * bound) << "res " << res << ": suspiciously exact";
  }
}

TEST(BakeTable, BicubicConvergesAtFourthOrder2D) {
  ModelNetwork net = test::random_model_network("12", {-0.7, -0.2}, {0.7, 1.0}, 14);
  auto max_err = [&](int res) {
    BakedTerm t = make_baked_term(bake_network(net, 200, res, nullptr, false));
    double err = 0;
    for (int i = 0; i < 97; ++i)
      for (int j = 0; j < 89; ++j) {
        const double s[2] = {-0.7 + 1.4 * (i + 0.37) / 97, -0.2 + 1.2 * (j + 0.61) / 89};
        auto ref = material_function(net)(s, 1, 0);
        err = std::max(err, std::abs(eval_baked_2d(t, {s[0], s[1]}).f - ref[0]));
      }
    return err;
  };
  const double e1 = max_err(12), e2 = max_err(24), e3 = max_err(48);
  EXPECT_GT(e1 / e2, 10.0) << e1 << " " << e2;
  EXPECT_GT(e2 / e3, 12.0) << e2 << " " << e3;
}

// The fast value-gradient-Hessian path agrees with the general jet path.
TEST(BakeTable, FastPathMatchesJet) {
  ModelNetwork net = test::random_model_network("25", {-0.2, -230.0}, {1.0, 230.0}, 15);
  BakedTerm t = make_baked_term(bake_network(net, 200, 40));
  for (int k = 0; k < 200; ++k) {
    const double s[2] = {-0.5 + 1.8 * ((k * 37) % 200) / 200.0, -400 + 800 * ((k * 53) % 200) / 200.0};
    double jet[10];
    eval_baked_jet(t, s, 2, jet);
    BakedJet2 r = eval_baked_2d(t, {s[0], s[1]});
    EXPECT_NEAR(r.f, jet[0], 1e-12 * (1 + std::abs(jet[0])));
    EXPECT_NEAR(r.g[0], jet[1], 1e-10 * (1 + std::abs(jet[1])));
    EXPECT_NEAR(r.g[1], jet[2], 1e-10 * (1 + std::abs(jet[2])));
    EXPECT_NEAR(r.H(0, 0), jet[3], 1e-9 * (1 + std::abs(jet[3])));
    EXPECT_NEAR(r.H(0, 1), jet[4], 1e-9 * (1 + std::abs(jet[4])));
    EXPECT_NEAR(r.H(1, 1), jet[5], 1e-9 * (1 + std::abs(jet[5])));
  }
}

// Baking a cubic polynomial is exact: cubic Hermite reproduces cubics, bicubic reproduces
// bicubics, everywhere inside the box.
TEST(BakeTable, ReproducesCubicsExactly) {
  test::Poly p;
  p.c[0][0] = 0.5; p.c[1][0] = -1; p.c[2][0] = 2; p.c[3][0] = 0.7;
  p.c[0][1] = 0.3; p.c[1][1] = -0.4; p.c[0][2] = 1.1; p.c[2][1] = 0.25; p.c[1][2] = -0.6; p.c[0][3] = 0.2;
  BakedTerm t = make_baked_term(bake_function(term_by_name("01"), {-1, -2}, {1.5, 1}, {7, 5}, test::poly_function(p, 2), nullptr, false));
  for (int k = 0; k < 50; ++k) {
    const double s[2] = {-1 + 2.5 * k / 49.0, -2 + 3.0 * ((k * 7) % 50) / 49.0};
    double jet[10];
    eval_baked_jet(t, s, 3, jet);
    EXPECT_NEAR(jet[0], p(s[0], s[1], 0, 0), 1e-12);
    EXPECT_NEAR(jet[1], p(s[0], s[1], 1, 0), 1e-11);
    EXPECT_NEAR(jet[5], p(s[0], s[1], 0, 2), 1e-10);
    EXPECT_NEAR(jet[7], p(s[0], s[1], 2, 1), 1e-9);
  }
}
