#pragma once
// IPC's smooth log barrier (Li et al. 2020): for a distance d,
//   b(d) = -(d - dhat)^2 ln(d / dhat)   for 0 < d < dhat,   0 for d >= dhat,
// C2 at dhat, infinite as d -> 0, so that a line search that never crosses d = 0 keeps every
// vertex outside the colliders. Returned divided by dhat (units of length), so that
// kappa A b / dhat with kappa in Pa is an energy and kappa |b'| a pressure.
//   b'  = -(2 (d - dhat) ln(d/dhat) + (d - dhat)^2 / d)
//   b'' = -(2 ln(d/dhat) + 4 (d - dhat)/d - (d - dhat)^2 / d^2)
namespace yarnhom::sim {

struct BarrierValue {
  double b = 0, db = 0, d2b = 0;
};

// d <= 0 gives b = +inf.
BarrierValue barrier(double d, double dhat);

}  // namespace yarnhom::sim
