// Cloth pinched between a moving capsule and something fixed (sim/contact.hpp, issue 35): a
// static rod, a floor plane collider, the sheet's own pinned row, another sheet's pinned row
// (cloth against cloth). The capsule must be held back
// (it lags its path, and the step says by how much), never pass through, and the state stays
// finite. Every step is checked with the exact test (contact_intersections; for the plane,
// every vertex on its free side).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sim/contact.hpp"
#include "sim/rectangle.hpp"
#include "sim/simulation.hpp"
#include "tests/common/sim_contact_checks.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;

namespace {

// A weightless n x n sheet of side L in the plane z = z0, centred on the origin.
Scene flat_sheet(int n, double L, double z0) {
  Scene s;
  s.mesh = make_rectangle(L, L, n, n);
  for (int v = 0; v < s.mesh.num_vertices(); ++v) s.mesh.x.row(v) << s.mesh.rest(v, 0) - L / 2, s.mesh.rest(v, 1) - L / 2, z0;
  s.gravity.setZero();
  s.integrator = Integrator::Linearized;
  return s;
}

// A capsule along y over the whole sheet, its axis at height z, moving down by `drop` in 0.6 s.
CapsuleObstacle pressing_capsule(double z, double drop, double r = 0.015) {
  CapsuleObstacle cap;
  cap.a = Eigen::Vector3d(0.0, -0.2, z);
  cap.b = Eigen::Vector3d(0.0, 0.2, z);
  cap.radius = r;
  cap.path = {{0.0, 0, 0, 0}, {0.6, 0, 0, -drop}};
  return cap;
}


struct PinchRun {
  SimResult result;
  int steps = 0;
  double last_z = 0;  // the moving capsule's axis height at the end
};

// Runs s (the moving capsule is obstacle point `moving` (its first end), starting at height z0
// and dropping `drop` in 0.6 s), checking every step: finite, no intersection, every vertex above
// each plane collider, and the recorded lag = the capsule's distance from its path.
PinchRun run_checked(const Scene& s, int moving, double z0, double drop) {
  const Problem P = test::contact_check_problem(s);
  PinchRun out;
  out.result = run_simulation(s, test::contact_test_material(), 0.2, SimSettings{}, [&](int frame, const SimResult& R) {
    ++out.steps;
    ASSERT_TRUE(R.x.allFinite()) << "frame " << frame;
    ASSERT_TRUE(R.obstacles.allFinite()) << "frame " << frame;
    std::string what;
    EXPECT_FALSE(contact_intersections(P, R.x, R.obstacles, &what)) << "frame " << frame << ": " << what;
    for (const Collider& c : s.colliders)
      for (int v = 0; v < s.mesh.num_vertices(); ++v)
        EXPECT_GT(collider_distance(c, R.x.segment<3>(3 * v)), 0.0) << "frame " << frame << ", vertex " << v;
    const double path_z = z0 - drop * std::min(1.0, frame * s.dt / 0.6);
    EXPECT_NEAR(R.steps.back().obstacle_lag, R.obstacles[3 * moving + 2] - path_z, 1e-9) << "frame " << frame;
  });
  out.last_z = out.result.obstacles[3 * moving + 2];
  return out;
}

}  // namespace

TEST(Pinch, ACapsulePressingASheetOnARodIsHeldBackAbove) {
  // The sheet 2 mm above a static rod (top at z = 0); the capsule (bottom 3 mm above the sheet)
  // would go 2 cm through the rod's top.
  Scene s = flat_sheet(4, 0.12, 0.002);
  CapsuleObstacle rod;
  rod.a = Eigen::Vector3d(-0.2, 0.0, -0.03);
  rod.b = Eigen::Vector3d(0.2, 0.0, -0.03);
  rod.radius = 0.03;
  s.obstacles.capsules = {rod, pressing_capsule(0.02, 0.06)};
  s.frames = 14;
  const PinchRun run = run_checked(s, 2, 0.02, 0.06);
  ASSERT_TRUE(run.result.finite);
  EXPECT_EQ(run.steps, 14);
  EXPECT_GT(run.last_z, 0.015);                        // the capsule's bottom above the rod's top
  EXPECT_GT(run.result.steps.back().obstacle_lag, 0.01);  // its path is 0.02 - 0.047 = -2.7 cm there
}

TEST(Pinch, ACapsulePressingASheetOnAFloorIsHeldBackAbove) {
  Scene s = flat_sheet(4, 0.12, 0.002);
  Collider floor;  // z = 0, normal +z
  s.colliders = {floor};
  s.obstacles.capsules = {pressing_capsule(0.02, 0.06)};
  s.frames = 14;
  const PinchRun run = run_checked(s, 0, 0.02, 0.06);
  ASSERT_TRUE(run.result.finite);
  EXPECT_EQ(run.steps, 14);
  EXPECT_GT(run.last_z, 0.015);
  EXPECT_GT(run.result.steps.back().obstacle_lag, 0.01);
}

TEST(Pinch, ACapsulePressingOnASheetsPinnedRowIsHeldBackAbove) {
  // The sheet's middle row (y = 0, under the capsule's... across it) pinned: a capsule along x
  // over that row, moving down, meets the pinned vertices and cannot push them.
  const int n = 4;
  Scene s = flat_sheet(n, 0.12, 0.0);
  Handle pin;
  for (int i = 0; i <= n; ++i) pin.vertices.push_back(rectangle_vertex(n, i, n / 2));
  s.handles = {pin};
  CapsuleObstacle cap = pressing_capsule(0.02, 0.06);
  cap.a = Eigen::Vector3d(-0.2, 0.0, 0.02);
  cap.b = Eigen::Vector3d(0.2, 0.0, 0.02);
  s.obstacles.capsules = {cap};
  s.frames = 14;
  const PinchRun run = run_checked(s, 0, 0.02, 0.06);
  ASSERT_TRUE(run.result.finite);
  EXPECT_EQ(run.steps, 14);
  EXPECT_GT(run.last_z, 0.015);
  EXPECT_GT(run.result.steps.back().obstacle_lag, 0.01);
}

TEST(Pinch, ACapsulePressingASheetOntoAnotherSheetsPinnedRowIsHeldBackAbove) {
  // Cloth pinched against other cloth: a free sheet 3 mm above a second sheet whose middle row
  // (y = 0) is pinned; a capsule along x over that row, moving down, presses the upper sheet onto
  // the lower one, which cannot give way there. The carry of the upper sheet into the lower one
  // (sim/contact.hpp: make_move_safe) is bounded by CCD, not undone; the capsule must still stop
  // above both layers, and no layer may cross the other.
  const int n = 4;
  const double L = 0.12;
  const Scene one = flat_sheet(n, L, 0.0);
  const int nv = one.mesh.num_vertices();
  Scene s = one;
  s.mesh.rest.resize(2 * nv, 2);
  s.mesh.x.resize(2 * nv, 3);
  s.mesh.tris.resize(2 * one.mesh.num_triangles(), 3);
  for (int v = 0; v < nv; ++v) {
    s.mesh.rest.row(v) = one.mesh.rest.row(v);
    s.mesh.rest.row(nv + v) = one.mesh.rest.row(v) + Eigen::RowVector2d(2 * L, 0);
    s.mesh.x.row(v) = one.mesh.x.row(v);
    s.mesh.x.row(nv + v) = one.mesh.x.row(v) + Eigen::RowVector3d(0, 0, 0.003);
  }
  s.mesh.tris << one.mesh.tris, (one.mesh.tris.array() + nv).matrix();
  finish_mesh(s.mesh);
  s.self_collision = true;
  Handle pin;  // the lower sheet's middle row
  for (int i = 0; i <= n; ++i) pin.vertices.push_back(rectangle_vertex(n, i, n / 2));
  s.handles = {pin};
  CapsuleObstacle cap = pressing_capsule(0.02, 0.06);
  cap.a = Eigen::Vector3d(-0.2, 0.0, 0.02);
  cap.b = Eigen::Vector3d(0.2, 0.0, 0.02);
  s.obstacles.capsules = {cap};
  s.frames = 14;
  const PinchRun run = run_checked(s, 0, 0.02, 0.06);
  ASSERT_TRUE(run.result.finite);
  EXPECT_EQ(run.steps, 14);
  EXPECT_GT(run.last_z, 0.015);  // the capsule's bottom above both layers (the upper at 3 mm)
  EXPECT_GT(run.result.steps.back().obstacle_lag, 0.01);
  // The upper sheet's middle row stays above the lower one's (the layers never swap).
  for (int i = 0; i <= n; ++i) {
    const int lo = rectangle_vertex(n, i, n / 2);
    EXPECT_GT(run.result.x[3 * (nv + lo) + 2], run.result.x[3 * lo + 2]) << "column " << i;
  }
}
