// Warm and cold starts of the producer (issue 10): on stocktiny and on the paper's stockinette,
// terms 0 and 02, every node where both converge has the same Psi (relative 1e-6), or the two
// found different local minima, each of them physical: certified to have the rest state's
// topology (every stored node is), a positive definite Hessian (a minimum, not a saddle) and
// Psi above Psi0. No in-plane node lies below the rest energy. Before the collision filter,
// 27 of the 81 cold nodes of the stockinette's term 02 lay below Psi0 (yarns had passed
// through each other).
//
// The test runs stocktiny at the quick preset and the stockinette at the tiny preset (its
// corners: 100 % biaxial stretch among them). YARNHOM_WARM_COLD_PRESET=quick runs the
// stockinette at the quick preset too (docs/rve.md section 5 records that run).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "tests/common/yarn_support.hpp"
#include "yarn/rve/energy_density.hpp"
#include "numerics/hessian_factor.hpp"
#include "produce/produce.hpp"
#include "yarn/rve/rest.hpp"

using namespace yarnhom;
using namespace yarnhom::numerics;
using namespace yarnhom::yarn;

namespace {

void check_warm_and_cold(const Pattern& p, const std::string& preset) {
  ProduceOptions opt;
  opt.preset = preset;
  opt.terms = parse_term_list("0,02");
  opt.threads = 2;
  ProduceReport rw, rc;
  const Dataset warm = produce(p, opt, &rw);
  opt.warm_start = false;
  const Dataset cold = produce(p, opt, &rc);
  EXPECT_TRUE(rw.failures.empty()) << rw.failures.size() << " warm nodes failed";
  EXPECT_TRUE(rc.failures.empty()) << rc.failures.size() << " cold nodes failed";
  EXPECT_EQ(rw.refused + rc.refused, 0);
  EXPECT_GT(rw.min_separation, 0.25 * 2 * p.radius);
  EXPECT_GT(rc.min_separation, 0.25 * 2 * p.radius);

  // The producer's own rest tile (stress free: the period relaxed too).
  const RestTile tile = relax_tile(p, opt.material);
  const RveProblem& rve = tile.rve;
  const RveState& rest = tile.state;
  const double psi0 = warm.psi0;
  ASSERT_NEAR(cold.psi0, psi0, 1e-12 * psi0);
  int nodes = 0, second = 0;
  for (size_t t = 0; t < warm.terms.size(); ++t) {
    const TermData& W = warm.terms[t];
    const TermData& C = cold.terms[t];
    ASSERT_EQ(W.n, C.n) << W.term.name;
    const int d = W.term.dim();
    for (int i = 0; i < W.n; ++i) {
      ++nodes;
      Strain s = Strain::Zero();
      for (int k = 0; k < d; ++k) {
        ASSERT_EQ(W.strain[i * d + k], C.strain[i * d + k]);
        s[W.term.indices[k]] = W.strain[i * d + k];
      }
      // Terms 0 and 02 are in-plane: nothing lies below the rest energy.
      EXPECT_GE(W.raw[i], -1e-9 * psi0) << "warm below rest at s_x " << s[0] << ", s_y " << s[2];
      EXPECT_GE(C.raw[i], -1e-9 * psi0) << "cold below rest at s_x " << s[0] << ", s_y " << s[2];
      if (std::abs(W.raw[i] - C.raw[i]) <= 1e-6 * (psi0 + W.raw[i])) continue;
      // Two different minima: both are stored (hence certified); the cold one, solved again
      // from the rest state here, is a minimum with a valid certificate.
      ++second;
      RveState st = rest;
      const DensityResult r = energy_density(rve, s, st);
      std::printf("  %s: second minimum at s_x %.4g, s_y %.4g: warm Psi - Psi0 = %.6g, cold %.6g J/m^2\n",
                  p.name.c_str(), s[0], s[2], W.raw[i], C.raw[i]);
      if (!r.report.converged()) {
        ADD_FAILURE() << "cold solve at s_x " << s[0] << ", s_y " << s[2] << " does not reproduce";
        continue;
      }
      EXPECT_NEAR(r.psi - psi0, C.raw[i], 1e-6 * r.psi);
      EXPECT_TRUE(st.certificate.valid) << st.certificate.failure;
      std::vector<Eigen::Triplet<double>> trip;
      Eigen::VectorXd g;
      rve.evaluate(s, st, &g, &trip);
      HessianFactor H(rve.num_dofs());
      H.assemble(trip);
      EXPECT_TRUE(H.factor(0.0)) << "cold state at s_x " << s[0] << ", s_y " << s[2] << " is not a minimum";
    }
  }
  std::printf("  %s, preset %s: %d nodes, %d with a second (certified) minimum; closest centrelines warm %.3f, cold %.3f x 2r\n",
              p.name.c_str(), preset.c_str(), nodes, second, rw.min_separation / (2 * p.radius),
              rc.min_separation / (2 * p.radius));
  // Measured on stocktiny at the quick preset: 10 of 102 nodes with the yarnhom-2025 constants,
  // 36 of 102 with the calibrated default (contact 10x stiffer relative to the yarn: more
  // sliding states), every one certified and within a few percent of the warm energy. A bound
  // that catches a solver gone astray, not a target.
  EXPECT_LT(second, nodes / 2) << "warm and cold mostly agree";
}

}  // namespace

TEST(WarmCold, StocktinyQuickPresetAgreesOrFindsCertifiedMinima) {
  YARN_REQUIRE_SHARED_PATTERNS();
  check_warm_and_cold(read_pyp(yarn::testing::shared_pattern("stocktiny")), "quick");
}

TEST(WarmCold, PaperStockinetteAgreesOrFindsCertifiedMinima) {
  YARN_REQUIRE_SHARED_PATTERNS();
  const char* env = std::getenv("YARNHOM_WARM_COLD_PRESET");
  check_warm_and_cold(read_pyp(yarn::testing::shared_pattern("stockinette")), env ? env : "tiny");
}
