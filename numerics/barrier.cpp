#include "numerics/barrier.hpp"

#include <cmath>
#include <limits>

namespace yarnhom::numerics {

double barrier(double z, double* d1, double* d2) {
  // b = -(z-1)^2 ln z;  b' = -2 (z-1) ln z - (z-1)^2 / z;
  // b'' = -2 ln z - 4 (z-1)/z + (z-1)^2 / z^2.  Zero from z = 1 on; infinite at z <= 0.
  const double inf = std::numeric_limits<double>::infinity();
  double b = 0, b1 = 0, b2 = 0;
  if (!(z > 0.0)) {
    b = inf, b1 = -inf, b2 = inf;
  } else if (z < 1.0) {
    const double lz = std::log(z), zm = z - 1.0, iz = 1.0 / z;
    b1 = -2.0 * zm * lz - zm * zm * iz;
    b2 = -2.0 * lz - 4.0 * zm * iz + zm * zm * iz * iz;
    b = -zm * zm * lz;
  }
  if (d1) *d1 = b1;
  if (d2) *d2 = b2;
  return b;
}

BarrierValue distance_barrier(double d, double dhat) {
  BarrierValue r;
  if (d >= dhat) return r;
  if (!(d > 0)) {
    r.b = std::numeric_limits<double>::infinity();
    return r;
  }
  double d1, d2;
  r.b = dhat * barrier(d / dhat, &d1, &d2);
  r.db = d1;
  r.d2b = d2 / dhat;
  return r;
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

}  // namespace yarnhom::numerics
