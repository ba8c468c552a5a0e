#include "numerics/pcg.hpp"

#include <cmath>

namespace yarnhom::numerics {

PcgResult pcg(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& apply_A,
              const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& apply_M_inverse, const Eigen::VectorXd& b,
              int max_iterations, const std::function<bool(const Eigen::VectorXd& x, const Eigen::VectorXd& z)>& stop) {
  PcgResult res;
  res.x = Eigen::VectorXd::Zero(b.size());
  Eigen::VectorXd r = b;
  Eigen::VectorXd z = apply_M_inverse(r);
  Eigen::VectorXd d = z;
  double rz = r.dot(z);
  if (!std::isfinite(rz)) return res;
  if (rz == 0) {  // b = 0: x = 0 solves it
    res.converged = stop(res.x, z);
    return res;
  }
  for (int k = 0; k < max_iterations; ++k) {
    const Eigen::VectorXd q = apply_A(d);
    const double dq = d.dot(q);
    ++res.iterations;
    if (!(dq > 0) || !std::isfinite(dq)) return res;
    const double a = rz / dq;
    res.x += a * d;
    r -= a * q;
    z = apply_M_inverse(r);
    if (!z.allFinite()) return res;
    if (stop(res.x, z)) {
      res.converged = true;
      return res;
    }
    const double rz_next = r.dot(z);
    d = z + (rz_next / rz) * d;
    rz = rz_next;
  }
  return res;
}

}  // namespace yarnhom::numerics
