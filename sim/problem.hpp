#pragma once
// Everything about a simulation that does not change from step to step: the mesh and its rest
// shape, the material, masses, gravity, colliders and damping.
#include <vector>

#include "numerics/psd_projection.hpp"
#include "sim/collider.hpp"
#include "sim/element_rest.hpp"
#include "sim/hessian_model.hpp"
#include "material/material_fn.hpp"
#include "sim/mesh.hpp"

namespace yarnhom::sim {

struct Problem {
  Mesh mesh;
  std::vector<ElementRest> rest;
  MaterialFn material;
  Eigen::VectorXd vertex_area;  // [n] lumped rest area, m^2
  Eigen::VectorXd mass;         // [n] areal_density * vertex_area, kg
  double areal_density = 0;     // kg/m^2
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);  // m/s^2
  std::vector<Collider> colliders;
  double dhat = 1e-3;           // barrier activation distance, m
  double kappa = 0;             // barrier stiffness, Pa (energy kappa A b(d)/dhat per vertex)
  double rayleigh_alpha = 0;    // mass-proportional damping, 1/s
  double rayleigh_beta = 0;     // stiffness-proportional damping, s
  double air_drag = 0;          // drag on the normal velocity, kg/(m^2 s) (force -c A (v.n) n)
  double friction_eps_v = 1e-3; // m/s, friction's sticking velocity threshold (sim/friction.hpp); the scenes
                                // set 1e-3 l per second, l the sheet's rest diagonal
  int friction_updates = 0;     // re-solves of a step with lambda and T taken at its solution (IPC's lag update)
  HessianModel hessian = HessianModel::Split;  // PSD model of the element Hessians (sim/hessian_model.hpp)
  numerics::EigenFilter eigen_filter = numerics::EigenFilter::Clamp;  // ... and what it does to a negative eigenvalue
};

// Rest elements, vertex areas and masses from the mesh. areal_density may be 0 (no inertia
// and no weight: quasi-static scenes without gravity).
Problem make_problem(Mesh mesh, MaterialFn material, double areal_density);

// Mesh positions as the simulator's 3n vector (vertex-major) and back.
Eigen::VectorXd flatten(const Eigen::MatrixX3d& x);
Eigen::MatrixX3d unflatten(const Eigen::VectorXd& x);

}  // namespace yarnhom::sim
