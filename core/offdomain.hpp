#pragma once
// Off-domain points of the strain-concentration loss L_S (spec section 6): x_o uniform in the
// band between the box [-1,1]^d and the box [-1.5,1.5]^d, with n_o the outward unit normal of
// the nearest face of [-1,1]^d. In a corner of the band (outside in both coordinates) the
// nearest face is taken to be the one the point is farthest beyond (the direction of the
// gradient of the max-norm): our choice, since there the two faces are equally near their
// common edge.
//
// Sampling is exact, not rejection: the band's area splits into pieces of known measure, so
// one uniform picks the piece and the others place the point inside it. Host and device.
#include <cstdint>

#include "core/rng.hpp"

namespace yarnhom {

inline constexpr double kOffDomainOuter = 1.5;

// Writes point j of the stream `key`: x[d] and n[d].
template <class T>
YH_HD inline void offdomain_point(int d, uint64_t key, uint64_t j, T* x, T* n) {
  const double u0 = rng_uniform(key, 4 * j + 0);
  const double u1 = rng_uniform(key, 4 * j + 1);
  const double u2 = rng_uniform(key, 4 * j + 2);
  const double w = kOffDomainOuter - 1.0;  // band width 0.5
  if (d == 1) {
    const double side = u0 < 0.5 ? -1.0 : 1.0;
    x[0] = T(side * (1.0 + w * u1));
    n[0] = T(side);
    return;
  }
  // d == 2: the band is 4 edge strips (2 x w each) and 4 corner squares (w x w each).
  const double edge = 2.0 * w, corner = w * w, total = 4.0 * edge + 4.0 * corner;
  double pick = u0 * total;
  if (pick < 4.0 * edge) {
    const int face = static_cast<int>(pick / edge);  // 0:+x 1:-x 2:+y 3:-y
    const int axis = face / 2;
    const double sign = (face % 2 == 0) ? 1.0 : -1.0;
    x[axis] = T(sign * (1.0 + w * u1));
    x[1 - axis] = T(-1.0 + 2.0 * u2);
    n[axis] = T(sign);
    n[1 - axis] = T(0);
  } else {
    const int c = static_cast<int>((pick - 4.0 * edge) / corner) & 3;
    const double sx = (c & 1) ? -1.0 : 1.0, sy = (c & 2) ? -1.0 : 1.0;
    const double ex = w * u1, ey = w * u2;  // excess beyond the faces
    x[0] = T(sx * (1.0 + ex));
    x[1] = T(sy * (1.0 + ey));
    const bool along_x = ex >= ey;
    n[0] = T(along_x ? sx : 0.0);
    n[1] = T(along_x ? 0.0 : sy);
  }
}

}  // namespace yarnhom
