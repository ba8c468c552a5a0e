#pragma once
// What the simulator's contact tests share (tests/sim/): the smooth test material they simulate,
// and the scene's contact problem as run_simulation builds it, for checking every frame with
// the exact intersection test (sim::contact_intersections).
#include <functional>

#include "sim/contact.hpp"
#include "sim/obstacles.hpp"
#include "sim/rectangle.hpp"
#include "sim/problem.hpp"
#include "sim/scene.hpp"
#include "tests/common/poly_material.hpp"

namespace yarnhom::test {

inline const MaterialFn& contact_test_material() {
  static const MaterialFn m = poly_material_fn(simple_cloth_terms(), -0.5);
  return m;
}

// The scene's contact problem: its obstacles, self-collision and d_hat, the cloth's edges.
inline sim::Problem contact_check_problem(const sim::Scene& s) {
  sim::Problem P = sim::make_problem(s.mesh, contact_test_material(), 0.2);
  P.obstacles = s.obstacles;
  sim::finish_obstacles(P.obstacles);
  P.self_collision = true;
  P.dhat = s.dhat;
  P.edges = sim::cloth_edges(P.mesh);
  return P;
}

// Two 2 cm sheets of k x k quads, the upper one 0.6 mm above the lower (d_hat 1 mm) and moved by
// upper(v) = its vertex v's (dx, dy, dz) from the lower one's, and a capsule just under them: every
// pair kind within d_hat (the contact tests' FD check, the broad phase's cache).
inline sim::Problem two_sheets_over_a_capsule(int k, double self_friction,
                                              const std::function<Eigen::Vector3d(int)>& upper) {
  const sim::Mesh m = sim::make_rectangle(0.02, 0.02, k, k);
  sim::Mesh two;
  const int n = m.num_vertices();
  two.rest.resize(2 * n, 2);
  two.x.resize(2 * n, 3);
  two.tris.resize(2 * m.num_triangles(), 3);
  for (int v = 0; v < n; ++v) {
    two.rest.row(v) = m.rest.row(v);
    two.rest.row(n + v) = m.rest.row(v) + Eigen::RowVector2d(0.05, 0);
    two.x.row(v) << m.rest(v, 0), m.rest(v, 1), 0.0;
    const Eigen::Vector3d d = upper(v);
    two.x.row(n + v) << m.rest(v, 0) + d.x(), m.rest(v, 1) + d.y(), d.z();
  }
  two.tris << m.tris, (m.tris.array() + n).matrix();
  sim::finish_mesh(two);
  sim::Problem P = sim::make_problem(two, contact_test_material(), 0.2);
  P.self_collision = true;
  P.self_friction = self_friction;
  P.dhat = 1e-3;
  P.kappa = 50;
  sim::CapsuleObstacle cap;
  cap.a = Eigen::Vector3d(-0.01, 0.0105, -0.0016);
  cap.b = Eigen::Vector3d(0.03, 0.0095, -0.0016);
  cap.radius = 0.001;
  P.obstacles.capsules = {cap};
  sim::finish_obstacles(P.obstacles);
  P.edges = sim::cloth_edges(P.mesh);
  return P;
}

}  // namespace yarnhom::test
