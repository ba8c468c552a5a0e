#include "sim/barrier.hpp"

#include <cmath>
#include <limits>

namespace yarnhom::sim {

BarrierValue barrier(double d, double dhat) {
  BarrierValue r;
  if (d >= dhat) return r;
  if (!(d > 0)) {
    r.b = std::numeric_limits<double>::infinity();
    return r;
  }
  const double e = d - dhat, L = std::log(d / dhat);
  r.b = -e * e * L / dhat;
  r.db = -(2 * e * L + e * e / d) / dhat;
  r.d2b = -(2 * L + 4 * e / d - e * e / (d * d)) / dhat;
  return r;
}

}  // namespace yarnhom::sim
