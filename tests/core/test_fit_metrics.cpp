// The fit metrics of core/fit_metrics.hpp on data whose answers are known by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/fit_metrics.hpp"
#include "tests/common/analytic_term.hpp"

using namespace yarnhom;

TEST(FitMetrics, KnownValuesAndVerdicts) {
  TermData d;
  d.term = term_by_name("02");
  d.n = 4;
  d.strain = {0, 0, 1, 0, 0, 1, 1, 1};
  d.energy = {0, 1, 2, 4};                      // range 4
  d.gradient = {3, 4, 0, 0, 0, 0, 6, 8};        // |g| = 5, 0, 0, 10: mean 3.75
  // Prediction: energy off by 0.1 at points 1 and 3; gradient off by (0.3, 0.4) at point 0.
  std::vector<double> jet = {0, 1.1, 2, 4.1, 3.3, 0, 0, 6, 4.4, 0, 0, 8};
  const FitQuality all = fit_quality(d, jet);
  EXPECT_EQ(all.n, 4);
  EXPECT_DOUBLE_EQ(all.energy_range, 4.0);
  EXPECT_NEAR(all.energy_rmse, std::sqrt(0.02 / 4), 1e-15);
  EXPECT_NEAR(all.energy_rel, std::sqrt(0.005) / 4, 1e-15);
  EXPECT_DOUBLE_EQ(all.grad_mean, 3.75);
  EXPECT_NEAR(all.grad_rms, std::sqrt(0.25 / 4), 1e-15);
  EXPECT_NEAR(all.grad_rel, 0.25 / 3.75, 1e-15);
  // On a subset: ranges and means stay those of all the points.
  const FitQuality sub = fit_quality(d, jet, {1, 2});
  EXPECT_EQ(sub.n, 2);
  EXPECT_NEAR(sub.energy_rmse, std::sqrt(0.01 / 2), 1e-15);
  EXPECT_DOUBLE_EQ(sub.grad_rms, 0.0);
  EXPECT_DOUBLE_EQ(sub.grad_mean, 3.75);
  EXPECT_TRUE(sub.ok());
  EXPECT_EQ(fit_verdict(sub), "ok");
  // all: energy 1.77% < 3% ok; gradient 6.7% < 10% ok. Make the gradient fail.
  jet[4] = 5.3;  // point 0's d/ds_0 off by 2.3
  const FitQuality bad = fit_quality(d, jet);
  EXPECT_TRUE(bad.energy_ok());
  EXPECT_FALSE(bad.grad_ok());
  EXPECT_EQ(fit_verdict(bad).rfind("FAILS: gradient error", 0), 0u) << fit_verdict(bad);
  EXPECT_THROW(fit_quality(d, jet, {4}), std::invalid_argument);
}

// The gradient is measured in box coordinates: each component scaled by its half-width, so a
// bending component (strain in 1/m over a box of +-200) counts as much as an in-plane one.
TEST(FitMetrics, GradientInBoxCoordinates) {
  TermData d;
  d.term = term_by_name("03");
  d.lower = {-0.5, -200};
  d.upper = {0.5, 200};  // half-widths 0.5 and 200
  d.n = 2;
  d.strain = {0, 0, 0.5, 100};
  d.energy = {0, 1};
  d.gradient = {2, 0, 0, 0.01};  // box-scaled: (1, 0) and (0, 2): mean |.| 1.5
  // Off by 0.005 J/m in dPsi/dII at point 1 only: box-scaled error 1 there.
  const std::vector<double> jet = {0, 1, 2, 0, 0, 0.015};
  const FitQuality q = fit_quality(d, jet);
  EXPECT_DOUBLE_EQ(q.grad_mean, 1.5);
  EXPECT_NEAR(q.grad_rms, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q.grad_rel, std::sqrt(0.5) / 1.5, 1e-12);
  EXPECT_FALSE(q.grad_ok());  // unscaled, this error (0.005 beside |g| ~ 1) would have passed
}

// The data's own inconsistency: zero for a quadratic on a grid (the trapezoid rule is exact
// for it), a known value when one node's gradient is off, -1 for scattered points.
// A quadratic sampled on a 5 x 5 grid over [-1, 1] x [-2, 2] (half-widths 1, 2), and its exact jet.
static TermData quadratic_grid(std::vector<double>& jet) {
  TermData d;
  d.term = term_by_name("01");
  d.lower = {-1, -2};
  d.upper = {1, 2};
  const int m = 5;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      const double x = -1 + 0.5 * i, y = -2 + 1.0 * j;
      d.strain.insert(d.strain.end(), {x, y});
      d.energy.push_back(x * x + 0.5 * x * y - 0.25 * y * y + x);
      d.gradient.insert(d.gradient.end(), {2 * x + 0.5 * y + 1, 0.5 * x - 0.5 * y});
    }
  d.n = m * m;
  jet.assign(3 * d.n, 0.0);
  for (int p = 0; p < d.n; ++p) {
    jet[p] = d.energy[p];
    jet[d.n + p] = d.gradient[2 * p];
    jet[2 * d.n + p] = d.gradient[2 * p + 1];
  }
  return d;
}

TEST(FitMetrics, DataInconsistencyOfAGrid) {
  std::vector<double> jet;
  const TermData d = quadratic_grid(jet);
  const FitQuality q = fit_quality(d, jet);
  EXPECT_NEAR(q.data_inconsistency, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(q.grad_rel, 0.0);
  // Node (2, 2)'s d/ds_0 off by 1: its two pairs along axis 0 each see 0.5 (x half-width 1);
  // 40 pairs in all.
  TermData bad = d;
  bad.gradient[2 * 12] += 1.0;
  const double mean = fit_quality(bad, jet).grad_mean;
  EXPECT_NEAR(data_inconsistency(bad, mean), std::sqrt(2 * 0.25 / 40) / mean, 1e-12);
  // The verdict of a failed fit on data that inconsistent says so.
  bad.gradient[2 * 12] += 1e3;
  const FitQuality qb = fit_quality(bad, jet);
  EXPECT_FALSE(qb.ok());
  EXPECT_NE(fit_verdict(qb).find("not smooth data"), std::string::npos) << fit_verdict(qb);
  // Scattered points are not a grid.
  TermData s = d;
  for (int p = 0; p < s.n; ++p) s.strain[2 * p] += 1e-3 * p;
  EXPECT_LT(data_inconsistency(s, 1.0), 0.0);
}

// The small-stress error of a 1D term: the relative gradient error over the points whose |dPsi|
// is 1-20 % of the largest. A network 25 % too stiff there passes the range-relative limits
// (the basket s_x term before the relative fit) and fails this one; 2D terms are not measured.
TEST(FitMetrics, SmallStressErrorSeesWhatTheRangeRelativeLimitsMiss) {
  const TermData d = test::analytic_term("0", -0.2, 1.0, 121, test::stiffening_psi, test::stiffening_dpsi);
  double gmax = 0;
  for (double g : d.gradient) gmax = std::max(gmax, std::abs(g));
  // The prediction: exact, except 25 % too stiff wherever |s| < 0.15 (the small strains).
  std::vector<double> jet(2 * d.n);
  int in_band = 0;
  for (int p = 0; p < d.n; ++p) {
    const double s = d.strain[p], g = d.gradient[p];
    jet[p] = d.energy[p] + (std::abs(s) < 0.15 ? 0.25 * d.energy[p] : 0.0);
    jet[d.n + p] = std::abs(s) < 0.15 ? 1.25 * g : g;
    const double a = std::abs(g);
    in_band += a >= 0.01 * gmax && a <= 0.2 * gmax && std::abs(s) < 0.15;
  }
  const FitQuality q = fit_quality(d, jet);
  EXPECT_TRUE(q.energy_ok()) << q.energy_rel;
  EXPECT_TRUE(q.grad_ok()) << q.grad_rel;
  ASSERT_GT(q.small_stress_n, in_band);  // the band reaches past |s| = 0.15 too
  // RMS of 0.25 over the in-band points inside |s| < 0.15, 0 over the others.
  EXPECT_NEAR(q.small_stress_rel, 0.25 * std::sqrt(double(in_band) / q.small_stress_n), 1e-12);
  EXPECT_FALSE(q.small_stress_ok());
  EXPECT_FALSE(q.ok());
  EXPECT_NE(fit_verdict(q).find("small stresses off by"), std::string::npos) << fit_verdict(q);
  // The exact prediction passes; points outside the band (e.g. only the largest) measure nothing.
  for (int p = 0; p < d.n; ++p) jet[d.n + p] = d.gradient[p], jet[p] = d.energy[p];
  EXPECT_DOUBLE_EQ(fit_quality(d, jet).small_stress_rel, 0.0);
  EXPECT_EQ(fit_quality(d, jet, {d.n - 1}).small_stress_rel, -1.0);
  EXPECT_TRUE(fit_quality(d, jet, {d.n - 1}).small_stress_ok());
}

// 2D terms have no small-stress error.
TEST(FitMetrics, SmallStressErrorIsFor1DTermsOnly) {
  TermData d;
  d.term = term_by_name("02");
  d.n = 4;
  d.strain = {0, 0, 1, 0, 0, 1, 1, 1};
  d.energy = {0, 1, 2, 4};
  d.gradient = {3, 4, 0.5, 0, 0, 0.5, 6, 8};
  const std::vector<double> jet = {0, 1, 2, 4, 3, 1, 0, 6, 4, 0, 1, 8};
  const FitQuality q = fit_quality(d, jet);
  EXPECT_EQ(q.small_stress_rel, -1.0);
  EXPECT_EQ(q.small_stress_n, 0);
}

// Issue 36's rule: where the data disagree with themselves by more than the gradient limit (data
// G >= 10 %), a fit passes when its gradient error is below 1.25 x data G, and the verdict says
// that it passed by that rule. One node's d/ds_0 in the data off by 5 on the exact quadratic's
// grid: the exact fit misses that node by 5 (gradient error 1.79 x data G: fails, with the data
// rule's limit named); a fit halfway to the bad node (0.89 x data G) passes by the data rule; a
// fit within 10 % passes by the limit whatever data G.
TEST(FitMetrics, RoughDataPassesByTheDataRuleWithinAQuarterAboveDataG) {
  std::vector<double> exact;
  TermData d = quadratic_grid(exact);
  d.gradient[2 * 12] += 5.0;
  const FitQuality q_exact = fit_quality(d, exact);
  ASSERT_TRUE(q_exact.rough_data()) << q_exact.data_inconsistency;
  // grad error sqrt(25 / 25) = 1, data G sqrt(2 (2.5)^2 / 40) = 0.559, both over the same mean.
  EXPECT_NEAR(q_exact.grad_rel / q_exact.data_inconsistency, 1.0 / std::sqrt(2 * 6.25 / 40), 1e-12);
  EXPECT_TRUE(q_exact.energy_ok());
  EXPECT_FALSE(q_exact.grad_ok());
  EXPECT_FALSE(q_exact.ok());
  EXPECT_EQ(fit_rule(q_exact), "-");
  EXPECT_NE(fit_verdict(q_exact).find("or 1.25 x data G ="), std::string::npos) << fit_verdict(q_exact);
  EXPECT_NE(fit_verdict(q_exact).find("not smooth data"), std::string::npos) << fit_verdict(q_exact);

  std::vector<double> halfway = exact;
  halfway[d.n + 12] += 2.5;
  const FitQuality q_half = fit_quality(d, halfway);
  EXPECT_NEAR(q_half.grad_rel / q_half.data_inconsistency, 0.5 / std::sqrt(2 * 6.25 / 40), 1e-12);
  EXPECT_FALSE(q_half.grad_within_limit()) << q_half.grad_rel;
  EXPECT_TRUE(q_half.grad_within_data());
  EXPECT_TRUE(q_half.ok());
  EXPECT_EQ(fit_rule(q_half), "data");
  EXPECT_EQ(fit_verdict(q_half).rfind("ok by the data rule", 0), 0u) << fit_verdict(q_half);

  std::vector<double> close = exact;
  close[d.n + 12] += 4.5;  // 0.5 off: 0.1 / mean < 10 %
  const FitQuality q_close = fit_quality(d, close);
  EXPECT_TRUE(q_close.grad_within_limit()) << q_close.grad_rel;
  EXPECT_EQ(fit_rule(q_close), "limit");
  EXPECT_EQ(fit_verdict(q_close), "ok");
  // The energy limit is not relaxed by rough data.
  std::vector<double> off = halfway;
  for (int p = 0; p < d.n; ++p) off[p] += (p % 2 ? 0.5 : -0.5);
  const FitQuality q_off = fit_quality(d, off);
  EXPECT_FALSE(q_off.energy_ok()) << q_off.energy_rel;
  EXPECT_FALSE(q_off.ok());
}
