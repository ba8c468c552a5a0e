// The fit metrics of core/fit_metrics.hpp on data whose answers are known by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "core/fit_metrics.hpp"

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
