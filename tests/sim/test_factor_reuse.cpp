// Factor reuse within a Newton solve (sim/newton.hpp, NewtonSettings::reuse_cg): the iterations
// after a step's first solve by conjugate gradients preconditioned with the step's last
// Cholesky factor. The hanging sheet's Newton run with it ends where the fresh-factor run
// ends (within the Newton tolerance's reach), every step converged, with fewer factorizations.
#include <gtest/gtest.h>

#include "sim/rectangle.hpp"
#include "sim/simulation.hpp"
#include "tests/common/poly_material.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;

namespace {

const MaterialFn& material() { return test::simple_cloth_material(); }

struct Totals {
  int iterations = 0, factorizations = 0, cg = 0, reused = 0;
};
Totals totals(const SimResult& r) {
  Totals t;
  for (const StepRecord& s : r.steps) {
    t.iterations += s.iterations;
    t.factorizations += s.factorizations;
    t.cg += s.cg_iterations;
    t.reused += s.reused;
  }
  return t;
}

}  // namespace

TEST(FactorReuse, HangingSheetEndsWhereTheFreshFactorRunEndsWithFewerFactorizations) {
  Scene s = builtin_scene("hang", 8);
  s.frames = 20;
  const SimResult fresh = run_simulation(s, material(), 0.3, SimSettings{});
  s.newton.reuse_cg = 8;
  const SimResult reuse = run_simulation(s, material(), 0.3, SimSettings{});
  ASSERT_TRUE(fresh.finite);
  ASSERT_TRUE(reuse.finite);
  EXPECT_TRUE(fresh.all_converged);
  EXPECT_TRUE(reuse.all_converged);
  const Totals f = totals(fresh), r = totals(reuse);
  // Every fresh iteration factors its own matrix (no diagonal shifts in dynamics); none reuses.
  EXPECT_EQ(f.factorizations, f.iterations);
  EXPECT_EQ(f.cg, 0);
  EXPECT_EQ(f.reused, 0);
  // With reuse: some iterations solved by CG, each one factorization fewer.
  EXPECT_GT(r.reused, 0);
  EXPECT_GE(r.cg, r.reused);
  EXPECT_EQ(r.factorizations + r.reused, r.iterations);
  EXPECT_LT(r.factorizations, f.factorizations);
  // The same end state: within a few Newton tolerances (rms step 1e-2 l h per step; 20 steps,
  // each ending within its tolerance), the difference measured at every vertex (measured:
  // 0.23 mm, about one tolerance).
  ASSERT_EQ(fresh.x.size(), reuse.x.size());
  const double diag = std::hypot(s.mesh.rest.col(0).maxCoeff() - s.mesh.rest.col(0).minCoeff(),
                                 s.mesh.rest.col(1).maxCoeff() - s.mesh.rest.col(1).minCoeff());
  const double tol = 1e-2 * diag * s.dt;
  const double dmax = (fresh.x - reuse.x).cwiseAbs().maxCoeff();
  EXPECT_LT(dmax, 4 * tol) << "tolerance " << tol;
  std::printf("hang 8x8, 20 frames: iterations %d / %d, factorizations %d / %d, CG %d, max difference %.3g m (tol %.3g)\n",
              f.iterations, r.iterations, f.factorizations, r.factorizations, r.cg, dmax, tol);
}
