#pragma once
// What the simulator's contact tests share (tests/sim/): the smooth test material they simulate,
// and the scene's contact problem as run_simulation builds it, for checking every frame with
// the exact intersection test (sim::contact_intersections).
#include "sim/contact.hpp"
#include "sim/obstacles.hpp"
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

}  // namespace yarnhom::test
