#include "sim/hinge_angles.hpp"

#include <cmath>
#include <numbers>

#include "sim/dihedral_angle.hpp"

namespace yarnhom::sim {

// remainder(d, 2 pi) is d itself when |d| < pi (its quotient rounds to 0): the usual case, an
// angle near its reference, skips the library call (the same bits).
double unwrap_angle(double theta, double ref) {
  const double d = theta - ref;
  return ref + (std::abs(d) < std::numbers::pi ? d : std::remainder(d, 2 * std::numbers::pi));
}

std::vector<double> hinge_angles(const Mesh& m, const Eigen::VectorXd& x, const std::vector<double>* ref) {
  std::vector<double> out(size_t(3) * m.num_triangles(), 0.0);
  // Each angle on its own: the same values on any number of threads.
#pragma omp parallel for schedule(static) if (m.num_triangles() >= 1024)
  for (int t = 0; t < m.num_triangles(); ++t)
    for (int i = 0; i < 3; ++i) {
      const int f = m.flaps(t, i);
      if (f < 0) continue;
      const int a = m.tris(t, i), b = m.tris(t, (i + 1) % 3), c = m.tris(t, (i + 2) % 3);
      double theta = dihedral_angle(x.segment<3>(3 * a), x.segment<3>(3 * b), x.segment<3>(3 * c), x.segment<3>(3 * f));
      if (ref) theta = unwrap_angle(theta, (*ref)[3 * t + i]);
      out[3 * t + i] = theta;
    }
  return out;
}

}  // namespace yarnhom::sim
