// Static equilibria: a sheet hanging from two corners is held by clamp forces that add up to
// its weight; a strip of a homogeneous material stretched between two clamps carries, per
// unit undeformed width, the force dPsi/ds_x of the material at its middle's own strain.
#include <gtest/gtest.h>

#include "sim/integrators.hpp"
#include "sim/rectangle.hpp"
#include "tests/common/poly_material.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;
using Eigen::VectorXd;

TEST(Statics, HangingSheetClampForceEqualsItsWeight) {
  const int nx = 8, ny = 12;
  const double W = 0.2, H = 0.3, rho = 0.3;
  Mesh mesh = make_rectangle(W, H, nx, ny);
  // Hanging in the vertical x-z plane, wale (y) up.
  for (int v = 0; v < mesh.num_vertices(); ++v) mesh.x.row(v) << mesh.rest(v, 0), 0.0, mesh.rest(v, 1);
  Problem P = make_problem(mesh, test::poly_material_fn(test::simple_cloth_terms()), rho);
  const std::vector<int> pins = {rectangle_vertex(nx, 0, ny), rectangle_vertex(nx, nx, ny)};
  const DofMap D = make_dof_map(P.mesh.num_vertices(), pins);
  const HessianPattern pat = make_hessian_pattern(P.mesh, D);
  LinearSolver solver;
  VectorXd x = flatten(P.mesh.x), target = x;
  NewtonSettings opt;
  opt.tol_step = 1e-10;
  const StepStats st = static_solve(P, D, pat, solver, x, target, opt);
  ASSERT_TRUE(st.newton.converged) << st.newton.iterations << " iterations, step " << st.newton.step_norm;
  const VectorXd g = potential_energy_gradient(P, x);
  Eigen::Vector3d R = Eigen::Vector3d::Zero(), free_residual = Eigen::Vector3d::Zero();
  for (int v = 0; v < P.mesh.num_vertices(); ++v) {
    if (D.free_index[v] < 0)
      R += g.segment<3>(3 * v);
    else
      free_residual = free_residual.cwiseMax(g.segment<3>(3 * v).cwiseAbs());
  }
  const double weight = rho * W * H * 9.81;
  EXPECT_NEAR(R.z(), weight, 1e-6 * weight);
  EXPECT_LT(std::abs(R.x()) + std::abs(R.y()), 1e-6 * weight);
  EXPECT_LT(free_residual.maxCoeff(), 1e-6 * weight);
  // It sagged: the bottom edge's middle went down, the sheet stretched under its weight.
  const int bottom = rectangle_vertex(nx, nx / 2, 0);
  EXPECT_LT(x[3 * bottom + 2], -1e-4);
}
