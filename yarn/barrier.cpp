#include "yarn/barrier.hpp"

#include <cmath>
#include <limits>

namespace yarnhom::yarn {

double barrier(double z, double* d1, double* d2) {
  if (z >= 1.0) {
    if (d1) *d1 = 0;
    if (d2) *d2 = 0;
    return 0.0;
  }
  if (!(z > 0.0)) {
    const double inf = std::numeric_limits<double>::infinity();
    if (d1) *d1 = -inf;
    if (d2) *d2 = inf;
    return inf;
  }
  // b = -(z-1)^2 ln z;  b' = -2 (z-1) ln z - (z-1)^2 / z;
  // b'' = -2 ln z - 4 (z-1)/z + (z-1)^2 / z^2.
  const double lz = std::log(z), zm = z - 1.0, iz = 1.0 / z;
  if (d1) *d1 = -2.0 * zm * lz - zm * zm * iz;
  if (d2) *d2 = -2.0 * lz - 4.0 * zm * iz + zm * zm * iz * iz;
  return -zm * zm * lz;
}

double segment_barrier_energy(const Vec12& q, const BarrierParams& p, Vec12* g, Mat12* H) {
  const double Dmin = p.dmin * p.dmin, span = p.dhat * p.dhat - Dmin;
  // Cheap rejection first: the distance alone.
  const double D0 = segment_distance_squared(q);
  if (D0 >= p.dhat * p.dhat) {
    if (g) g->setZero();
    if (H) H->setZero();
    return 0.0;
  }
  if (!g && !H) return p.kappa * barrier((D0 - Dmin) / span);
  Vec12 gD;
  Mat12 HD;
  const double D = segment_distance_squared(q, &gD, H ? &HD : nullptr);
  double b1, b2;
  const double b = barrier((D - Dmin) / span, &b1, &b2);
  if (!std::isfinite(b)) {
    if (g) g->setConstant(std::numeric_limits<double>::quiet_NaN());
    if (H) H->setConstant(std::numeric_limits<double>::quiet_NaN());
    return b;
  }
  // dE/dq = kappa b' / span dD/dq;  d2E/dq2 = kappa (b'' / span^2 dD dD^T + b' / span d2D).
  if (g) *g = (p.kappa * b1 / span) * gD;
  if (H) *H = (p.kappa * b2 / (span * span)) * (gD * gD.transpose()) + (p.kappa * b1 / span) * HD;
  return p.kappa * b;
}

}  // namespace yarnhom::yarn
