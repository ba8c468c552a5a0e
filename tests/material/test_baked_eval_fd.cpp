// The baked evaluator's derivatives against central finite differences in double: the gradient
// from the value, the Hessian from the gradient and the third derivatives from the Hessian, in
// every sector (inside, the four edge bands, the four corners) and in 1D on both sides.
#include <gtest/gtest.h>

#include <random>

#include "bake/bake_table.hpp"
#include "material/baked_eval.hpp"
#include "tests/common/bake_test_util.hpp"

using namespace yarnhom;

namespace {

// Jet at s shifted by h along axis i.
std::vector<double> jet_at(const BakedTerm& t, const double* s, int i, double h) {
  double p[2] = {s[0], t.dim == 2 ? s[1] : 0.0};
  p[i] += h;
  std::vector<double> j(10);
  eval_baked_jet(t, p, 3, j.data());
  return j;
}

}  // namespace

TEST(BakedEvalFD, TwoDimensionalEverySector) {
  ModelNetwork net = test::random_model_network("13", {-0.7, -170.0}, {0.7, 170.0}, 71);
  BakedTerm t = make_baked_term(bake_network(net, 200, 40));
  const double W[2] = {1.4, 340};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0.05, 0.95);
  int per_sector[9] = {};
  for (int k = 0; k < 450; ++k) {
    // Sector k % 9: pick the region along each axis (-1 below, 0 inside, 1 above).
    const int sec = k % 9, ax = sec % 3 - 1, ay = sec / 3 - 1;
    double s[2];
    const int a[2] = {ax, ay};
    const double lo[2] = {-0.7, -170}, hi[2] = {0.7, 170};
    for (int i = 0; i < 2; ++i)
      s[i] = a[i] == 0 ? lo[i] + W[i] * U(rng) : a[i] < 0 ? lo[i] - W[i] * U(rng) : hi[i] + W[i] * U(rng);
    per_sector[baked_sector(t, s)]++;
    const std::vector<double> j = jet_at(t, s, 0, 0);
    for (int i = 0; i < 2; ++i) {
      const double h = 1e-6 * W[i];
      const auto p = jet_at(t, s, i, h), m = jet_at(t, s, i, -h);
      // d/ds_i of each channel against the channel one order up.
      const double g = (p[0] - m[0]) / (2 * h);
      EXPECT_NEAR(g, j[1 + i], 1e-6 * (std::abs(j[1 + i]) + std::abs(j[0]) / W[i])) << "sector " << sec;
      for (int c = 0; c < 2; ++c) {  // gradient component c -> Hessian (c, i)
        const double fd = (p[1 + c] - m[1 + c]) / (2 * h);
        const double an = j[jet_ch2(2, std::min(c, i), std::max(c, i))];
        EXPECT_NEAR(fd, an, 1e-5 * (std::abs(an) + std::abs(j[1 + c]) / W[i])) << "sector " << sec << " H " << c << i;
      }
      for (int q = 0; q < 3; ++q) {  // Hessian (q) -> third derivative
        const JetPair e = jet_pair(2, q);
        const double fd = (p[3 + q] - m[3 + q]) / (2 * h);
        const int ny = e.i + e.j + i;
        const double an = j[jet_first(2, 3) + ny];
        EXPECT_NEAR(fd, an, 1e-5 * (std::abs(an) + std::abs(j[3 + q]) / W[i])) << "sector " << sec << " T " << q << i;
      }
    }
  }
  for (int s = 0; s < 9; ++s) EXPECT_EQ(per_sector[s], 50) << "sector " << s;
}

TEST(BakedEvalFD, OneDimensional) {
  ModelNetwork net = test::random_model_network("0", {-0.2}, {1.0}, 72);
  BakedTerm t = make_baked_term(bake_network(net, 200, 40));
  for (double x : {-1.0, -0.3, -0.1, 0.137, 0.5, 0.93, 1.2, 3.0}) {
    const double h = 1e-7;
    const auto j = jet_at(t, &x, 0, 0), p = jet_at(t, &x, 0, h), m = jet_at(t, &x, 0, -h);
    for (int o = 0; o < 3; ++o)
      EXPECT_NEAR((p[o] - m[o]) / (2 * h), j[o + 1], 1e-6 * (std::abs(j[o + 1]) + std::abs(j[o]))) << x << " order " << o;
  }
}
