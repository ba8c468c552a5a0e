// A time step's initial guess (sim/potential.hpp, feasible_prediction): vertex by vertex, a
// vertex whose inertial move would reach a collider stays put, every other vertex takes its whole
// move. The line search's global bound (max_feasible_step) would have shortened every vertex's
// move by the one impact, which froze a draped sheet (docs/sim.md).
#include <gtest/gtest.h>

#include "sim/potential.hpp"
#include "sim/rectangle.hpp"
#include "sim/simulation.hpp"
#include "tests/common/poly_material.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;

TEST(Prediction, OnlyTheVertexThatWouldReachAColliderStays) {
  Mesh mesh = make_rectangle(0.1, 0.1, 1, 1);
  for (int v = 0; v < 4; ++v) mesh.x(v, 2) = 0.01;
  Problem P = make_problem(mesh, test::poly_material_fn(test::simple_cloth_terms()), 0.3);
  Collider floor;
  floor.kind = Collider::Kind::Plane;  // z = 0
  P.colliders = {floor};
  const Eigen::VectorXd x = flatten(P.mesh.x);
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(x.size());
  dx[3 * 0 + 2] = -0.02;   // through the floor
  dx[3 * 1 + 2] = -0.005;  // halfway down
  dx[3 * 2 + 0] = 0.03;    // sideways
  dx[3 * 3 + 2] = 0.01;    // up
  const Eigen::VectorXd xn = feasible_prediction(P, x, dx);
  EXPECT_EQ(xn.segment<3>(0), x.segment<3>(0));
  for (int v = 1; v < 4; ++v) EXPECT_EQ(xn.segment<3>(3 * v), (x + dx).segment<3>(3 * v)) << v;
  // The global bound would have shortened every move to 0.9 x 0.5 of it.
  EXPECT_NEAR(max_feasible_step(P, x, dx), 0.45, 1e-12);
  // No collider: the whole move.
  P.colliders.clear();
  EXPECT_EQ(feasible_prediction(P, x, dx), x + dx);
}
