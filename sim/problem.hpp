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
#include "sim/obstacles.hpp"

namespace yarnhom::sim {

// A seam's stitch: vertices a and b pulled together by a zero-rest-length spring, the start's
// difference offset0 = x_a - x_b fading out over the sewing time (sim/garment.hpp).
struct Stitch {
  int a = 0, b = 0;
  Eigen::Vector3d offset0 = Eigen::Vector3d::Zero();
};

struct Problem {
  Mesh mesh;
  std::vector<ElementRest> rest;
  MaterialFn material;
  MaterialValueFn material_value;  // its psi alone where cheaper (empty: material's psi)
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
  // Surface contact (sim/contact.hpp): the cloth against itself and against obstacles, with the
  // barrier's dhat and kappa above. Off in a bare Problem; the scenes turn it on.
  bool self_collision = false;
  double self_friction = 0;     // Coulomb mu between cloth layers
  ObstacleSet obstacles;        // capsules and meshes (finish_obstacles done)
  std::vector<Eigen::Vector2i> edges;  // the cloth's unique edges (set with contact)
  std::vector<Stitch> stitches;  // seams (sim/garment.hpp)
  double stitch_stiffness = 0;   // N/m per stitch
  double sew_time = 0;           // s over which the stitches' offsets fade to 0
  double gravity_delay = 0;      // s: gravity acts from then on (dynamic steps)
  std::vector<int> vertex_rep;   // per vertex, a representative shared by stitched vertices (contact
                                 // pairs between primitives with stitched vertices are skipped); empty: itself
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
