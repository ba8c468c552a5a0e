#pragma once
// Parallel transport and reference twist (Bergou et al. 2008, 2010), written once for any
// scalar (double, or Jet for exact derivatives).
#include <cmath>

#include "yarn/jet.hpp"

namespace yarnhom::yarn {

// Rotates v by the rotation that takes unit a to unit b about a x b, without dividing by
// |a x b| (smooth at a = b, which is where the time-parallel transport of a frame is
// evaluated at every accepted Newton step):  P v = c v + w x v + w (w.v)/(1 + c),
// c = a.b, w = a x b. Undefined only for antiparallel a, b.
template <class T, class S>
inline V3<T> transport(const V3<S>& a, const V3<T>& b, const V3<S>& v) {
  const T c = dot(V3<T>(T(a.x), T(a.y), T(a.z)), b);
  const V3<T> at(T(a.x), T(a.y), T(a.z));
  const V3<T> vt(T(v.x), T(v.y), T(v.z));
  const V3<T> w = cross(at, b);
  return c * vt + cross(w, vt) + (dot(w, vt) / (c + 1.0)) * w;
}
template <class T>
inline V3<T> transport_same(const V3<T>& a, const V3<T>& b, const V3<T>& v) {
  const T c = dot(a, b);
  const V3<T> w = cross(a, b);
  return c * v + cross(w, v) + (dot(w, v) / (c + 1.0)) * w;
}

// Signed angle from u to d about the unit axis t (u, d perpendicular to t), in (-pi, pi].
template <class T>
inline T signed_angle(const V3<T>& u, const V3<T>& d, const V3<T>& t) {
  using std::atan2;
  return atan2(dot(cross(u, d), t), dot(u, d));
}

// The branch of `angle` (known mod 2 pi) closest to `hint`: keeps reference twist
// continuous across updates, so a full turn is never lost or invented.
inline double unwrap_near(double angle, double hint) {
  const double two_pi = 2.0 * M_PI;
  return angle + two_pi * std::round((hint - angle) / two_pi);
}

}  // namespace yarnhom::yarn
