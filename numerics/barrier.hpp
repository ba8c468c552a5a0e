#pragma once
// IPC's smooth log barrier (Li et al. 2020), one implementation for both simulators.
//
// In normalized form, b(z) = -(z - 1)^2 ln z for 0 < z < 1, 0 for z >= 1, +inf for z <= 0:
// C2 at z = 1, infinite as z -> 0. The yarn simulators apply it to a normalized squared
// segment distance (segment_barrier_energy below); the continuum simulator to a vertex's
// distance d from a collider, as distance_barrier(d, dhat) = dhat b(d / dhat) (units of
// length: kappa A b / dhat with kappa in Pa is an energy and kappa |b'| a pressure).
//
// A log barrier on the closest distance between two segments (IPC, Li et al. 2020, shifted to a
// minimum separation as codimensional IPC does): no configuration with the segments at or
// below d_min has finite energy, and the barrier is exactly zero beyond the activation
// distance d_hat, so it only acts on pairs that came close.
//
//   z = (D - d_min^2) / (d_hat^2 - d_min^2),   D = squared closest distance (segment_distance.hpp)
//   b(z) = -(z - 1)^2 ln z   for 0 < z < 1,   0 for z >= 1,   +inf for z <= 0
//   E = kappa b(z)
//
// b, b' and b'' all vanish at z = 1 (C2 at the activation distance: the sparsity pattern and
// the Newton model see no jump when a pair enters), and b grows like -ln z near d_min. Working
// in the squared distance keeps every type's formula polynomial (no square roots).
#include "numerics/segment_distance.hpp"

namespace yarnhom::numerics {

// b(z) and its first two derivatives (zero for z >= 1; +inf, and derivatives -inf/+inf, for z <= 0).
double barrier(double z, double* d1 = nullptr, double* d2 = nullptr);

// dhat b(d / dhat) with its first two derivatives in d: b = -(d - dhat)^2 ln(d / dhat) / dhat,
// b' = -(2 (d - dhat) ln(d/dhat) + (d - dhat)^2 / d) / dhat... (the chain rule of b(z)).
// Zero for d >= dhat; b = +inf (and derivatives 0) for d <= 0.
struct BarrierValue {
  double b = 0, db = 0, d2b = 0;
};
BarrierValue distance_barrier(double d, double dhat);

struct BarrierParams {
  double dmin = 0;   // m: the separation that is never reached (the barrier is +inf there)
  double dhat = 0;   // m: activation distance (> dmin): the barrier is zero beyond it
  double kappa = 0;  // J: the barrier's energy scale
};

// kappa b(z(D(q))) of the segment pair q = [a0, a1, b0, b1], with exact gradient and Hessian
// when asked (chain rule through D's own exact derivatives; the Hessian is not projected to
// be positive definite: the Newton solver's definiteness shift handles indefiniteness, and
// the exact Hessian keeps the assembled system checkable against finite differences).
// Returns 0 (and zero derivatives) beyond d_hat, +inf at or below d_min.
double segment_barrier_energy(const Vec12& q, const BarrierParams& p, Vec12* g = nullptr, Mat12* H = nullptr);

}  // namespace yarnhom::numerics
