// The simulator's iterative solver (--solver pcg: numerics/block_jacobi_pcg.hpp): the one-solve
// drape runs with it, every solve's CG iterations are counted, and a tight tolerance reproduces
// the direct solver's trajectory; a loose one stays close to it (each step is a shorter Newton
// step that the line search takes as it is).
#include <gtest/gtest.h>

#include "sim/simulation.hpp"
#include "tests/common/poly_material.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;

TEST(PcgSolver, OneSolveDrapeFollowsTheDirectSolversTrajectory) {
  const MaterialFn& m = test::simple_cloth_material();
  Scene s = builtin_scene("drape", 10);
  s.frames = 20;
  s.integrator = Integrator::Linearized;
  const SimResult direct = run_simulation(s, m, 0.2, SimSettings{});
  ASSERT_TRUE(direct.finite);
  EXPECT_EQ(direct.solver_solves, 0);  // a factorization counts no CG iterations
  auto with_pcg = [&](double tol) {
    SimSettings set;
    set.solver = SolverKind::Pcg;
    set.pcg_tolerance = tol;
    return run_simulation(s, m, 0.2, set);
  };
  const SimResult tight = with_pcg(1e-10), loose = with_pcg(1e-3);
  for (const SimResult* r : {&tight, &loose}) {
    ASSERT_TRUE(r->finite);
    EXPECT_TRUE(r->diverged.empty()) << r->diverged;
    EXPECT_EQ(r->steps.size(), direct.steps.size());
    EXPECT_EQ(r->solver_name, "pcg (block Jacobi, CPU)");
    EXPECT_GE(r->solver_solves, long(r->steps.size()));
    EXPECT_GT(r->solver_iterations, 3 * r->solver_solves);  // it iterated
  }
  EXPECT_LT(loose.solver_iterations, tight.solver_iterations);
  const double size = direct.x.cwiseAbs().maxCoeff();
  EXPECT_LT((tight.x - direct.x).cwiseAbs().maxCoeff(), 1e-6 * size);
  EXPECT_LT((loose.x - direct.x).cwiseAbs().maxCoeff(), 0.1 * size);  // 3.8e-2 measured: a sheet still falling
  std::printf("last frame against the direct solve (max |dx| / max |x|): tight %.2e, loose %.2e; CG iterations "
              "per solve %.1f / %.1f\n",
              (tight.x - direct.x).cwiseAbs().maxCoeff() / size, (loose.x - direct.x).cwiseAbs().maxCoeff() / size,
              double(tight.solver_iterations) / tight.solver_solves,
              double(loose.solver_iterations) / loose.solver_solves);
}

TEST(PcgSolver, AutoRunsTheGpusCgForAMovingSceneOfSizeWhenAGpuIsThere) {
  // sim/simulation.hpp, resolve_auto_solver: what `--solver auto` becomes.
  Scene drape = builtin_scene("drape", 20);  // 441 vertices
  ASSERT_GE(drape.mesh.num_vertices(), kAutoGpuVertices);
  EXPECT_EQ(resolve_auto_solver(SolverKind::Auto, drape, true), SolverKind::PcgCuda);
  EXPECT_EQ(resolve_auto_solver(SolverKind::Auto, drape, false), SolverKind::Auto);  // no GPU
  drape.integrator = Integrator::Newton;
  EXPECT_EQ(resolve_auto_solver(SolverKind::Auto, drape, true), SolverKind::PcgCuda);
  // A quasi-static solve keeps the exact factorization.
  const Scene stretch = builtin_scene("stretch", 20);
  ASSERT_EQ(stretch.integrator, Integrator::Static);
  EXPECT_EQ(resolve_auto_solver(SolverKind::Auto, stretch, true), SolverKind::Auto);
  // A small sheet too (the tests' meshes), and any kind a user named.
  const Scene small = builtin_scene("drape", 10);
  ASSERT_LT(small.mesh.num_vertices(), kAutoGpuVertices);
  EXPECT_EQ(resolve_auto_solver(SolverKind::Auto, small, true), SolverKind::Auto);
  for (SolverKind k : {SolverKind::Cholmod, SolverKind::Ldlt, SolverKind::Pcg})
    EXPECT_EQ(resolve_auto_solver(k, drape, true), k);
}
