#pragma once
// The dihedral angles of every hinge of the shell on a continuous branch.
//
// atan2 gives a dihedral angle in (-pi, pi]; when a flap folds past its neighbour (the free
// edge of a soft knit curls, and a coarse mesh puts a whole curl into one hinge) it jumps by
// 2 pi, the bending strain and the energy jump with it, and a Newton line search stalls against
// that wall. So a simulation carries each hinge's angle from step to step and evaluates the
// next positions on the branch nearest it: theta = ref + remainder(atan2(...) - ref, 2 pi).
// Exact as long as no hinge turns by more than pi within one step. (There is no self-contact:
// past pi the flap passes through its neighbour, and the material's energy keeps rising.)
#include <Eigen/Core>
#include <vector>

#include "sim/mesh.hpp"

namespace yarnhom::sim {

// The value of theta + 2 pi k nearest ref.
double unwrap_angle(double theta, double ref);

// 3 per triangle (edge i of triangle t at 3t + i; 0 for a boundary edge), on the branch
// nearest ref (same layout) when given, else in (-pi, pi].
std::vector<double> hinge_angles(const Mesh& mesh, const Eigen::VectorXd& x, const std::vector<double>* ref = nullptr);

}  // namespace yarnhom::sim
