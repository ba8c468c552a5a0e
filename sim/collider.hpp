#pragma once
// Analytic colliders (a plane, a sphere) with the signed distance of a point and its
// derivatives, and the first time a straight motion reaches the surface (continuous collision
// detection, for the line search: IPC's filtered line search never leaves the feasible set).
#include <Eigen/Core>

namespace yarnhom::sim {

struct Collider {
  enum class Kind { Plane, Sphere };
  Kind kind = Kind::Plane;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // plane: a point on it; sphere: its centre
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ(); // plane: unit normal towards the free side
  double radius = 0;                                 // sphere
  double friction = 0;                               // Coulomb coefficient mu with the cloth (sim/friction.hpp); 0: frictionless
};

// Distance to the surface, positive on the free side; gradient and Hessian in x if asked.
double collider_distance(const Collider& c, const Eigen::Vector3d& x, Eigen::Vector3d* grad = nullptr,
                         Eigen::Matrix3d* hess = nullptr);

// Largest t in [0, 1] with distance(x + s p) > 0 for all s in [0, t) (1 when never reached);
// the caller scales it back (e.g. by 0.8) to stay strictly on the free side.
double collider_time_of_impact(const Collider& c, const Eigen::Vector3d& x, const Eigen::Vector3d& p);

}  // namespace yarnhom::sim
