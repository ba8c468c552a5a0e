#include "bake/rest_check.hpp"

#include <cmath>
#include <cstdio>

#include "core/scaled_eigen.hpp"

namespace yarnhom {

namespace {
const char* kStrainNames[6] = {"s_x", "s_a", "s_y", "II_x", "II_a", "II_y"};
}

std::string RestCheck::summary() const {
  char buf[512];
  std::string out;
  if (stable) {
    std::snprintf(buf, sizeof buf, "rest: stable (d2Psi/ds2 at s = 0 positive definite, smallest scaled eigenvalue %.3g)",
                  scaled_eigenvalues[0]);
    out = buf;
  } else {
    // Name the strains that dominate the weakest direction (in scaled strains, so that units
    // do not decide).
    std::string dir;
    const double m = weakest.cwiseAbs().maxCoeff();
    for (int i = 0; i < 6; ++i)
      if (std::abs(weakest[i]) >= 0.3 * m) dir += (dir.empty() ? "" : ", ") + std::string(kStrainNames[i]);
    std::snprintf(buf, sizeof buf,
                  "rest: UNSTABLE: d2Psi/ds2 at s = 0 has a negative direction (scaled eigenvalue %.3g, mostly %s); "
                  "diagonal",
                  scaled_eigenvalues[0], dir.c_str());
    out = buf;
    for (int i = 0; i < 6; ++i) {
      std::snprintf(buf, sizeof buf, " %s %.3g", kStrainNames[i], hess(i, i));
      out += buf;
    }
    out += ". A cloth of this material leaves its rest by itself: the networks are wrong near s = 0 (docs/accuracy.md)";
  }
  std::snprintf(buf, sizeof buf, "; in-plane stress at rest %.3g %.3g %.3g N/m", grad[0], grad[1], grad[2]);
  return out + buf;
}

RestCheck check_rest(const BakedMaterial& mat, double tolerance) {
  RestCheck r;
  const MaterialEval e = eval_material(mat, Strain6::Zero());
  r.grad = e.grad;
  r.hess = 0.5 * (e.hess + e.hess.transpose());
  const ScaledEigen se = scaled_eigen(r.hess);
  r.scaled_eigenvalues = se.values;
  r.weakest = se.weakest;
  r.stable = se.stable(tolerance);
  return r;
}

std::string rve_rest_note(const std::vector<double>& rest_hessian) {
  if (rest_hessian.size() != 36) return "";
  const ScaledEigen se = scaled_eigen(Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(rest_hessian.data()));
  char buf[160];
  std::snprintf(buf, sizeof buf, "; the RVE's own rest (measured by produce): %s, smallest scaled eigenvalue %.3g",
                se.stable() ? "stable" : "UNSTABLE", se.values[0]);
  return buf;
}

}  // namespace yarnhom
