#include "yarn/rod/contact.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

namespace yarnhom::yarn {

double contact_kernel(double rho, double* d1, double* d2) {
  if (rho >= 1.0) {
    if (d1) *d1 = 0;
    if (d2) *d2 = 0;
    return 0.0;
  }
  // (1 - rho)^3 / rho = 1/rho - 3 + 3 rho - rho^2.
  if (d1) *d1 = -1.0 / (rho * rho) + 3.0 - 2.0 * rho;
  if (d2) *d2 = 2.0 / (rho * rho * rho) - 2.0;
  const double om = 1.0 - rho;
  return om * om * om / rho;
}

namespace {

struct Rule {
  int n;
  std::array<double, 6> s, w;  // on [0, 1], weights summing to 1
};

const Rule& gauss_rule(int n) {
  static const Rule rules[] = {
      {1, {0.5}, {1.0}},
      {2, {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)}, {0.5, 0.5}},
      {3, {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)}, {5.0 / 18, 8.0 / 18, 5.0 / 18}},
      {4,
       {0.5 - 0.5 * 0.8611363115940526, 0.5 - 0.5 * 0.3399810435848563, 0.5 + 0.5 * 0.3399810435848563,
        0.5 + 0.5 * 0.8611363115940526},
       {0.5 * 0.3478548451374538, 0.5 * 0.6521451548625461, 0.5 * 0.6521451548625461,
        0.5 * 0.3478548451374538}},
  };
  if (n < 1 || n > 4) throw std::invalid_argument("contact quadrature must have 1 to 4 points");
  return rules[n - 1];
}

}  // namespace

double segment_contact_energy(const Vec12& q, double La, double Lb, const ContactParams& c,
                              Vec12* g, Mat12* H) {
  const Rule& rule = gauss_rule(c.quadrature);
  const double inv4r2 = 1.0 / (4.0 * c.radius * c.radius);
  const double scale = c.kc * La * Lb;
  const Eigen::Vector3d a0 = q.segment<3>(0), a1 = q.segment<3>(3), b0 = q.segment<3>(6), b1 = q.segment<3>(9);
  if (g) g->setZero();
  if (H) H->setZero();
  double e = 0;
  for (int i = 0; i < rule.n; ++i) {
    const double s = rule.s[i];
    const Eigen::Vector3d pa = (1 - s) * a0 + s * a1;
    for (int j = 0; j < rule.n; ++j) {
      const double t = rule.s[j];
      const Eigen::Vector3d d = pa - ((1 - t) * b0 + t * b1);
      const double rho = d.squaredNorm() * inv4r2;
      if (rho >= 1.0) continue;
      double f1, f2;
      const double w = scale * rule.w[i] * rule.w[j];
      e += w * contact_kernel(rho, &f1, &f2);
      if (!g && !H) continue;
      // d rho / d d = 2 d inv4r2; coefficients of d in the four endpoints:
      const double cf[4] = {1 - s, s, -(1 - t), -t};
      const Eigen::Vector3d gd = w * f1 * 2.0 * inv4r2 * d;
      if (g)
        for (int k = 0; k < 4; ++k) g->segment<3>(3 * k) += cf[k] * gd;
      if (H) {
        const Eigen::Matrix3d Hd = w * (f2 * 4.0 * inv4r2 * inv4r2 * (d * d.transpose()) +
                                        f1 * 2.0 * inv4r2 * Eigen::Matrix3d::Identity());
        for (int k = 0; k < 4; ++k)
          for (int l = 0; l < 4; ++l) H->block<3, 3>(3 * k, 3 * l) += cf[k] * cf[l] * Hd;
      }
    }
  }
  return e;
}

}  // namespace yarnhom::yarn
