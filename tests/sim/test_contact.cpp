// Surface contact in whole simulations (sim/contact.hpp): the fold scene (a sheet folded over a
// thin rod onto itself) is checked every frame with the exact triangle-triangle test, and its
// layers did come within the barrier's reach; without self-collision the same fold intersects
// (so the check has teeth); with the one-solve step its handle's neighbours follow the handle.
// A capsule sweeping through a hanging sheet pushes it: no vertex's
// path relative to the capsule crosses its radius in any step. The contact Hessian triplets
// and gradient match finite differences of the contact energy.
#include <gtest/gtest.h>

#include <cstdio>

#include "numerics/segment_distance.hpp"
#include "sim/contact.hpp"
#include "sim/garment.hpp"
#include "sim/rectangle.hpp"
#include "sim/shell_energy.hpp"
#include "sim/simulation.hpp"
#include "tests/common/poly_material.hpp"
#include "tests/common/sim_contact_checks.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;

namespace {

// Smallest distance between cloth primitives sharing no vertex.
double closest_self_distance(const Problem& P, const Eigen::VectorXd& x) {
  Problem Q = P;
  Q.obstacles = ObstacleSet{};
  Q.dhat = 0.02;  // candidates within 2 cm
  double d = INFINITY;
  for (const ContactPair& c : contact_candidates(Q, x, x, Eigen::VectorXd(), Eigen::VectorXd()))
    d = std::min(d, numerics::contact_distance(c.kind, pair_coordinates(c, x, Eigen::VectorXd())));
  return d;
}

}  // namespace

TEST(Contact, FoldNeverIntersectsAndItsLayersTouch) {
  Scene s = builtin_scene("fold", 8);
  s.frames = 36;
  const Problem P = test::contact_check_problem(s);
  double closest = INFINITY;
  int checked = 0;
  const SimResult r = run_simulation(s, test::contact_test_material(), 0.2, SimSettings{}, [&](int frame, const SimResult& R) {
    std::string what;
    EXPECT_FALSE(contact_intersections(P, R.x, R.obstacles, &what)) << "frame " << frame << ": " << what;
    if (frame > 25) closest = std::min(closest, closest_self_distance(P, R.x));
    ++checked;
  });
  ASSERT_TRUE(r.finite);
  EXPECT_EQ(checked, 36);
  // The folded half lies on the other: its layers came within the barrier's reach.
  EXPECT_LT(closest, s.dhat);
  // ... and the edge was carried over: its vertices are at x > 0.1.
  EXPECT_GT(r.x[3 * rectangle_vertex(8, 0, 4)], 0.1);
}

TEST(Contact, FoldWithoutSelfCollisionIntersects) {
  Scene s = builtin_scene("fold", 8);
  s.frames = 36;
  s.self_collision = false;
  const Problem P = test::contact_check_problem(s);
  bool crossed = false;
  run_simulation(s, test::contact_test_material(), 0.2, SimSettings{}, [&](int, const SimResult& R) {
    crossed = crossed || contact_intersections(P, R.x, R.obstacles);
  });
  EXPECT_TRUE(crossed);
}

// The one-solve step on the fold: its handle moves 2.5 cm per step (1/30 s), half a quad of
// this mesh (one and a half of the scene's 24 x 24). Placed there before the solve, with the
// cloth left at x_n, the handle pulled the triangles next to it out, since one solve does not
// catch up (with the demo material, past the collapse guard by step 14: non-finite at step 16).
// Moved within the solve, with the cloth's first-order response (sim/newton.hpp), the cloth
// follows it.
TEST(Contact, FoldWithTheOneSolveStepFollowsItsHandle) {
  const int n = 8;
  Scene s = builtin_scene("fold", n);
  s.integrator = Integrator::Linearized;
  s.frames = 30;
  const Problem P = test::contact_check_problem(s);
  double at_handle = 0;  // the largest |s_x|, |s_a|, |s_y| of a triangle with a handle vertex
  int checked = 0;
  const SimResult r = run_simulation(s, test::contact_test_material(), 0.2, SimSettings{}, [&](int frame, const SimResult& R) {
    std::string what;
    EXPECT_FALSE(contact_intersections(P, R.x, R.obstacles, &what)) << "frame " << frame << ": " << what;
    const std::vector<Strain6> e = triangle_strains(P.mesh, P.rest, R.x);
    for (int t = 0; t < P.mesh.num_triangles(); ++t)
      for (int k = 0; k < 3; ++k)
        if (P.mesh.tris(t, k) % (n + 1) == 0)  // the handle: the left edge, i = 0
          at_handle = std::max({at_handle, std::abs(e[t][0]), std::abs(e[t][1]), std::abs(e[t][2])});
    ++checked;
  });
  ASSERT_TRUE(r.finite);
  EXPECT_EQ(checked, 30);
  // Placed first, the handle left its neighbours 0.41 behind (at frame 13); moved in the solve,
  // 0.10 at most (the Newton step: 0.02 up to frame 28).
  EXPECT_LT(at_handle, 0.2);
  EXPECT_GT(r.x[3 * rectangle_vertex(n, 0, n / 2)], 0.1);  // laid over the rod, on the right half
}

TEST(Contact, CapsuleSweepingThroughAHangingSheetPushesItWithoutCrossing) {
  // A 0.2 m sheet hanging in the x-z plane from its top row; a horizontal capsule (radius
  // 1.5 cm, along x, wider than the sheet) moves from y = -4 cm to y = +8 cm through it in 0.6 s.
  const int n = 8;
  const double L = 0.2, r = 0.015;
  Scene s;
  s.mesh = make_rectangle(L, L, n, n);
  for (int v = 0; v < s.mesh.num_vertices(); ++v) s.mesh.x.row(v) << s.mesh.rest(v, 0) - L / 2, 0.0, -s.mesh.rest(v, 1);
  Handle top;
  for (int i = 0; i <= n; ++i) top.vertices.push_back(rectangle_vertex(n, i, 0));
  s.handles = {top};
  CapsuleObstacle cap;
  cap.a = Eigen::Vector3d(-0.2, -0.04, -0.12);
  cap.b = Eigen::Vector3d(0.2, -0.04, -0.12);
  cap.radius = r;
  cap.friction = 0.2;
  cap.path = {{0.0, 0, 0, 0}, {0.6, 0, 0.12, 0}};
  s.obstacles.capsules = {cap};
  s.integrator = Integrator::Linearized;
  s.frames = 24;
  Eigen::VectorXd xprev = flatten(s.mesh.x), yprev;
  {
    ObstacleSet o = s.obstacles;
    finish_obstacles(o);
    yprev = obstacle_positions(o, 0.0);
  }
  const Problem P = test::contact_check_problem(s);
  int steps = 0;
  double pushed = 0;
  const SimResult res = run_simulation(s, test::contact_test_material(), 0.2, SimSettings{}, [&](int frame, const SimResult& R) {
    // In the capsule's frame (it translates), each vertex moves from p0 to p1: that path must
    // stay outside the radius around the axis.
    const Eigen::Vector3d a = R.obstacles.segment<3>(0), b = R.obstacles.segment<3>(3);
    const Eigen::Vector3d shift = a - yprev.segment<3>(0);
    for (int v = 0; v < s.mesh.num_vertices(); ++v) {
      const Eigen::Vector3d p0 = xprev.segment<3>(3 * v) + shift, p1 = R.x.segment<3>(3 * v);
      EXPECT_GT(numerics::segment_distance(p0, p1, a, b), r) << "vertex " << v << " crosses in step " << frame;
    }
    std::string what;
    EXPECT_FALSE(contact_intersections(P, R.x, R.obstacles, &what)) << "frame " << frame << ": " << what;
    for (int v = 0; v < s.mesh.num_vertices(); ++v) pushed = std::max(pushed, R.x[3 * v + 1]);
    xprev = R.x;
    yprev = R.obstacles;
    ++steps;
  });
  ASSERT_TRUE(res.finite);
  EXPECT_EQ(steps, 24);
  // The capsule went all the way (it was not held back) and pushed the sheet ahead of it.
  EXPECT_NEAR(res.obstacles[1], 0.08, 1e-9);
  EXPECT_GT(pushed, 0.08 + r);
}

TEST(Contact, ACapsulePinchingASheetOnARodLagsBehindItsPathAndSaysHowFar) {
  // A weightless sheet 2 mm above a rod (a static capsule along x, top at z = 0); a capsule
  // across it (along y) moves down through the rod: the sheet pinched between them holds it
  // back, so it stops above the rod and lags behind its path; each step's record says by how
  // much (steps.csv's obstacle_lag_m; the renders name it). Held from frame 8, and still at
  // frame 24, 6 frames after its path's end (tests/sim/test_pinch.cpp: the floor, pinned rows).
  const int n = 6;
  const double L = 0.2, r = 0.015;
  Scene s;
  s.mesh = make_rectangle(L, L, n, n);
  for (int v = 0; v < s.mesh.num_vertices(); ++v) s.mesh.x.row(v) << s.mesh.rest(v, 0) - L / 2, s.mesh.rest(v, 1) - L / 2, 0.002;
  s.gravity.setZero();
  CapsuleObstacle rod, cap;
  rod.a = Eigen::Vector3d(-0.2, 0.0, -0.03);
  rod.b = Eigen::Vector3d(0.2, 0.0, -0.03);
  rod.radius = 0.03;
  cap.a = Eigen::Vector3d(0.0, -0.2, 0.04);
  cap.b = Eigen::Vector3d(0.0, 0.2, 0.04);
  cap.radius = r;
  cap.path = {{0.0, 0, 0, 0}, {0.6, 0, 0, -0.06}};
  s.obstacles.capsules = {rod, cap};
  s.integrator = Integrator::Linearized;
  s.frames = 24;
  const Problem P = test::contact_check_problem(s);
  const SimResult res = run_simulation(s, test::contact_test_material(), 0.2, SimSettings{}, [&](int frame, const SimResult& R) {
    std::string what;
    EXPECT_FALSE(contact_intersections(P, R.x, R.obstacles, &what)) << "frame " << frame << ": " << what;
    // The lag recorded is the moving capsule's distance from its path's place at the step's end.
    const double path_z = 0.04 - 0.06 * std::min(1.0, frame / 30.0 / 0.6);
    EXPECT_NEAR(R.steps.back().obstacle_lag, R.obstacles[3 * 2 + 2] - path_z, 1e-9) << "frame " << frame;
  });
  ASSERT_TRUE(res.finite);
  EXPECT_GT(res.obstacles[3 * 2 + 2], r);                   // stopped above the rod
  EXPECT_GT(res.steps.back().obstacle_lag, 0.03);           // its path ends at z = -0.02
  EXPECT_EQ(res.steps.front().obstacle_lag, 0.0);           // free at first
}

TEST(Contact, EnergyGradientAndHessianMatchFiniteDifferences) {
  // Two small sheets 0.6 mm apart (dhat 1 mm) and a capsule under them, each pair kind active.
  const Problem P = test::two_sheets_over_a_capsule(2, 0, [](int v) { return Eigen::Vector3d(0.003 * (v % 2), 0.002, 0.0006 + 0.0001 * (v % 3)); });
  const Eigen::VectorXd x = flatten(P.mesh.x), y = obstacle_positions(P.obstacles, 0);
  std::vector<int> free(P.mesh.num_vertices());
  for (int v = 0; v < int(free.size()); ++v) free[v] = v;
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  std::vector<Eigen::Triplet<double>> trip;
  const double E = contact_energy(P, free, x, y, &g, &trip);
  ASSERT_GT(E, 0);
  ASSERT_TRUE(std::isfinite(E));
  const double h = 1e-8;
  Eigen::VectorXd gfd(x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    gfd[i] = (contact_energy(P, free, xp, y) - contact_energy(P, free, xm, y)) / (2 * h);
  }
  EXPECT_LT((g - gfd).norm(), 1e-5 * gfd.norm());
  // The assembled (projected) Hessian is symmetric PSD: v^T H v >= 0 for random v.
  Eigen::SparseMatrix<double> H(x.size(), x.size());
  H.setFromTriplets(trip.begin(), trip.end());
  const Eigen::MatrixXd Hl = Eigen::MatrixXd(H), Hf = Eigen::MatrixXd(Hl.selfadjointView<Eigen::Lower>());
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Hf).eigenvalues().minCoeff(), -1e-8 * Hf.norm());
  EXPECT_GT(Hf.norm(), 0);
}

TEST(Contact, PotentialWithoutThePairsIsThePotentialLessTheirEnergy) {
  // The step start's lower bound (sim/integrators.cpp rejects a prediction on it): the whole
  // potential less the contact pairs' barrier energy, which is > 0 here (all pair kinds active).
  const Problem P = test::two_sheets_over_a_capsule(2, 0, [](int v) { return Eigen::Vector3d(0.003 * (v % 2), 0.002, 0.0006 + 0.0001 * (v % 3)); });
  const Eigen::VectorXd x = flatten(P.mesh.x), y = obstacle_positions(P.obstacles, 0);
  const DofMap D = make_dof_map(P.mesh.num_vertices(), {});
  StepState S;
  S.dynamic = false;
  const double pairs = contact_energy(P, D.free_index, x, y);
  ASSERT_GT(pairs, 0);
  double shell_all = NAN, shell_without = NAN;
  const double all = potential_value(P, D, S, x, &shell_all);
  const double without = potential_value_without_pairs(P, D, S, x, &shell_without);
  EXPECT_EQ(shell_all, shell_without);
  EXPECT_LT(without, all);
  EXPECT_NEAR(all - without, pairs, 1e-12 * std::abs(all));
  // A known shell energy is used as it is.
  const double known = shell_all + 1.0;
  EXPECT_NEAR(potential_value_without_pairs(P, D, S, x, nullptr, &known), without + 1.0, 1e-12 * std::abs(all));
}

TEST(Contact, TshirtIsSewnOnTheMannequinWithoutIntersections) {
  // The coarsest T-shirt (8 cm grid), sewn faster than the scene's default (over 6 frames
  // instead of 15) and then hanging on the mannequin: checked every frame; the seams closed.
  Scene s = builtin_scene("tshirt", 1);
  s.sew_time = s.gravity_delay = 0.2;
  s.frames = 10;
  Problem P = test::contact_check_problem(s);
  P.vertex_rep = stitch_representatives(P.mesh.num_vertices(), s.stitches);
  ASSERT_GT(s.stitches.size(), 20u);
  const SimResult r = run_simulation(s, test::contact_test_material(), 0.2, SimSettings{}, [&](int frame, const SimResult& R) {
    std::string what;
    EXPECT_FALSE(contact_intersections(P, R.x, R.obstacles, &what)) << "frame " << frame << ": " << what;
  });
  ASSERT_TRUE(r.finite);
  EXPECT_EQ(r.frames_done, 10);
  double gap = 0;
  for (const Stitch& st : s.stitches) gap = std::max(gap, (r.x.segment<3>(3 * st.a) - r.x.segment<3>(3 * st.b)).norm());
  EXPECT_LT(gap, 0.01);  // every seam within 1 cm (started 32 cm apart)
  // The report's residual force takes the seams as they are at the last step (sewn: no rest
  // gap), not as they were at time 0 (32 cm apart: a residual of thousands of weights).
  std::printf("residual force of the last frame: rms %.3g, max %.3g vertex weights\n", r.residual_rms, r.residual_max);
  ASSERT_GT(r.residual_vertices, 0);
  EXPECT_LT(r.residual_rms, 100.0);
}
