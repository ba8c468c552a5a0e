// Generated patterns: valid, exact .pyp round trip, relax to an equilibrium that loads as
// one; the physical checks on them (and on the paper's stockinette): stretch raises
// the energy monotonically, shear is symmetric where the pattern is.
#include <gtest/gtest.h>

#include <map>

#include "tests/common/yarn_support.hpp"
#include "yarn/rve/energy_density.hpp"
#include "yarn/rod/generate.hpp"
#include "yarn/rve/relax.hpp"

using namespace yarnhom::yarn;

namespace {

const Pattern& relaxed(const std::string& name) {
  static std::map<std::string, Pattern> cache;
  auto it = cache.find(name);
  // "stockinette" here is the tiny generated one (0.1 mm yarn, straight at rest), whose tile is
  // stress free and mirror symmetric at its own period; the built-in one, at the paper's scale,
  // is pre-stressed at its period like the paper's file (tested below with it).
  if (it == cache.end())
    it = cache.emplace(name, relax_pattern(name == "stockinette" ? generate_stockinette({}) : builtin_pattern(name), Material{})).first;
  return it->second;
}

// Psi along one strain axis, each solve warm started from the previous one.
std::vector<DensityResult> sweep(const RveProblem& rve, int k, const std::vector<double>& ts) {
  RveState st = rve.initial_state();
  std::vector<DensityResult> out;
  for (double t : ts) {
    Strain s = Strain::Zero();
    s[k] = t;
    out.push_back(energy_density(rve, s, st));
    EXPECT_TRUE(out.back().report.converged()) << "axis " << k << " t " << t << ": " << out.back().report.summary();
  }
  return out;
}

}  // namespace

TEST(Generate, PatternsAreValidAndRoundTripThroughPyp) {
  for (const auto& name : builtin_pattern_names()) {
    const Pattern p = builtin_pattern(name);
    EXPECT_EQ(p.name, name);
    const Pattern q = parse_pyp(format_pyp(p), name + ".pyp");
    EXPECT_EQ(format_pyp(q), format_pyp(p)) << name;
    const Topology t = topology(q);
    EXPECT_GE(t.yarns.size(), 1u);
    for (int v = 0; v < q.size(); ++v) EXPECT_GT(stored_edge(q, t, v).norm(), 0.1 * q.radius);
  }
  EXPECT_THROW(builtin_pattern("argyle"), std::invalid_argument);
  WovenParams bad;
  bad.group = 3;
  EXPECT_THROW(generate_woven(bad), std::invalid_argument);
}

TEST(Generate, RelaxedPatternsLoadAsEquilibria) {
  for (const char* name : {"plain", "stockinette"}) {
    const Pattern& p = relaxed(name);
    const Pattern q = parse_pyp(format_pyp(p), "relaxed.pyp");
    const RveProblem rve(q, Material{});
    Eigen::VectorXd g;
    rve.evaluate(Strain::Zero(), rve.initial_state(), &g);
    EXPECT_LT(relative_residual(rve, g), 1e-9) << name;
  }
}

TEST(Generate, StretchRaisesStockinetteEnergyMonotonically) {
  const RveProblem rve(relaxed("stockinette"), Material{});
  for (int k : {0, 2}) {
    const auto r = sweep(rve, k, {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6});
    for (size_t i = 1; i < r.size(); ++i) {
      EXPECT_GT(r[i].psi, r[i - 1].psi) << "axis " << k << " step " << i;
      EXPECT_GT(r[i].grad[k], 0.0);
    }
  }
}

TEST(Generate, PaperStockinetteStretchRaisesEnergyBeyondItsMinimum) {
  // The built-in stockinette (the paper's scale) at its own period: like the published tile it
  // is not stress free there (it would widen by 4.5 %), so Psi dips before it rises along s_x.
  {
    const RveProblem rve(relax_pattern(builtin_pattern("stockinette"), Material{}), Material{});
    for (int k : {0, 2}) {
      const auto r = sweep(rve, k, {0.1, 0.2, 0.3, 0.4, 0.5});
      for (size_t i = 1; i < r.size(); ++i) EXPECT_GT(r[i].psi, r[i - 1].psi) << "built-in, axis " << k << " step " << i;
    }
  }
  YARN_REQUIRE_SHARED_PATTERNS();
  // The stored tile is not stress free under our material (dPsi/ds_y(0) < 0: it is slightly
  // compressed along the wale), so Psi dips before it rises along s_y: monotonic from 0.1 on.
  const RveProblem rve(read_pyp(yarnhom::yarn::testing::shared_pattern("stockinette")), Material{});
  for (int k : {0, 2}) {
    const auto r = sweep(rve, k, {0.1, 0.2, 0.3, 0.4, 0.5});
    for (size_t i = 1; i < r.size(); ++i) {
      EXPECT_GT(r[i].psi, r[i - 1].psi) << "axis " << k << " step " << i;
      EXPECT_GT(r[i].grad[k], 0.0);
    }
  }
}

TEST(Generate, ShearIsSymmetricForMirrorSymmetricPatterns) {
  // The plain weave and the stockinette are symmetric under x -> -x (the weave with z -> -z:
  // a half turn about y), which maps s_a to -s_a.
  for (const char* name : {"plain", "stockinette"}) {
    const RveProblem rve(relaxed(name), Material{});
    const auto plus = sweep(rve, 1, {0.2, 0.4}), minus = sweep(rve, 1, {-0.2, -0.4});
    for (size_t i = 0; i < plus.size(); ++i) {
      EXPECT_NEAR(plus[i].psi, minus[i].psi, 1e-8 * plus[i].psi) << name;
      EXPECT_NEAR(plus[i].grad[1], -minus[i].grad[1], 1e-6 * std::abs(plus[i].grad[1])) << name;
    }
  }
}

TEST(Generate, PeakedWeaveProfileRisesOnlyToTheInterlacing) {
  // Weft 0 of a five-harness satin passes over warp 0 only: with peak = 2 it lies lower at the
  // crossings beside the interlacing than a cosine does (2 u^2 - 1 = -0.14 against cos 72 deg =
  // +0.31 amplitudes), and rises to the same height over warp 0.
  auto weft0 = [](double peak) {
    WeaveParams p;
    p.radius = 1e-3;
    p.px = p.py = 11e-3;
    for (int i = 0; i < 5; ++i) {
      std::string row(5, '0');
      row[(3 * i) % 5] = '1';
      p.weave.push_back(row);
    }
    p.weft_amplitude = p.warp_amplitude = 1.8e-3;
    p.peak = peak;
    p.samples_weft = 200;
    const Pattern pat = generate_weave(p);
    const Topology t = topology(pat);
    const auto& y = t.yarns[0];
    std::vector<double> z;
    for (int k = 0; k < 5; ++k) {  // z over warp k, interpolated between the vertices around it
      const double xk = -p.px / 2 + (k + 0.5) * p.px / 5;
      for (size_t i = 0; i + 1 < y.size(); ++i) {
        const Eigen::Vector3d a = pat.x[y[i]], b = pat.x[y[i + 1]];
        if (a[0] <= xk && xk < b[0]) z.push_back((a[2] + (b[2] - a[2]) * (xk - a[0]) / (b[0] - a[0])) / p.radius);
      }
    }
    return z;
  };
  const auto cosine = weft0(1), peaked = weft0(2);
  ASSERT_EQ(cosine.size(), 5u);
  ASSERT_EQ(peaked.size(), 5u);
  EXPECT_NEAR(cosine[0], 1.8, 0.01);
  EXPECT_NEAR(peaked[0], 1.8, 0.01);
  for (int k : {1, 4}) {
    EXPECT_NEAR(cosine[k], 1.8 * std::cos(2 * M_PI / 5), 0.01);
    EXPECT_NEAR(peaked[k], 1.8 * (2 * std::pow(0.5 * (1 + std::cos(2 * M_PI / 5)), 2) - 1), 0.01);
  }
  WeaveParams bad;
  bad.peak = 0.5;
  bad.weave = {"10", "01"};
  bad.px = bad.py = 8e-3;
  EXPECT_THROW(generate_weave(bad), std::invalid_argument);
}
