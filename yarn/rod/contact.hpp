#pragma once
// Smooth yarn-yarn contact between two segments (Kaldor et al. 2008's integrated penalty,
// with a C2 kernel):
//
//   E = k_c L_a L_b  int_0^1 int_0^1 f(|x_a(s) - x_b(t)|^2 / (2r)^2) ds dt,
//   f(rho) = (1 - rho)^3 / rho  for rho < 1, else 0        (f, f', f'' vanish at rho = 1)
//
// x_a(s), x_b(t) the two centrelines, L_a, L_b their rest lengths, r the yarn radius (the
// centrelines touch at distance 2r), k_c = contact_stiffness * r (J/m^2). The double integral
// is evaluated with a tensor Gauss-Legendre rule; the energy is then an exact, C2 function of
// the 12 endpoint coordinates and its gradient and Hessian below are exact. The 1/rho barrier
// keeps centrelines from crossing.
#include <Eigen/Core>

namespace yarnhom::yarn {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

// f(rho) and its first two derivatives; zero for rho >= 1.
double contact_kernel(double rho, double* d1 = nullptr, double* d2 = nullptr);

struct ContactParams {
  double radius = 0;  // yarn radius r (m)
  double kc = 0;      // energy scale (J/m^2)
  int quadrature = 4; // Gauss points per segment
};

// q = [a0, a1, b0, b1] (segment a: a0 -> a1, segment b: b0 -> b1).
double segment_contact_energy(const Vec12& q, double La, double Lb, const ContactParams& c,
                              Vec12* g, Mat12* H);


}  // namespace yarnhom::yarn
