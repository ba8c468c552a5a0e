#pragma once
// The strain 6-vector every stage hands on (docs/conventions.md section 2):
//   s = (s_x, s_a, s_y, II_x, II_a, II_y)
// stretches along the course (x) and the wale (y), the shear s_a (the sine of the angle between
// the deformed axes, 0 at rest), and the second fundamental form's entries (1/m). The yarn RVE
// is solved at a given s (yarn/rve), the networks and baked tables are functions of s
// (material/), and the continuum simulator computes s per triangle (sim/shell_strain.hpp).
#include <Eigen/Core>

namespace yarnhom {

using Strain6 = Eigen::Matrix<double, 6, 1>;

}  // namespace yarnhom
