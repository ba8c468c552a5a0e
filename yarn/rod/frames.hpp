#pragma once
// Parallel transport and reference twist (Bergou et al. 2008, 2010), written once for any
// scalar (double, or Jet for exact derivatives).
#include <cmath>

#include "numerics/jet.hpp"

namespace yarnhom::yarn {

using numerics::V3;

// Rotates v by the rotation that takes unit a to unit b about a x b, without dividing by
// |a x b| (smooth at a = b, which is where the time-parallel transport of a frame is
// evaluated at every accepted Newton step):  P v = c v + w x v + w (w.v)/(1 + c),
// c = a.b, w = a x b. Undefined only for antiparallel a, b.
// Transport of a constant vector v from a constant axis a to a variable axis b: only b carries
// derivatives, so constant factors stay plain doubles (much cheaper with Jets).
template <class T>
inline V3<T> transport(const V3<double>& a, const V3<T>& b, const V3<double>& v) {
  const T c = b.x * a.x + b.y * a.y + b.z * a.z;
  const V3<T> w(b.z * a.y - b.y * a.z, b.x * a.z - b.z * a.x, b.y * a.x - b.x * a.y);  // a x b
  const T wv = w.x * v.x + w.y * v.y + w.z * v.z;
  const V3<T> wxv(w.y * v.z - w.z * v.y, w.z * v.x - w.x * v.z, w.x * v.y - w.y * v.x);
  const V3<T> cv(c * v.x, c * v.y, c * v.z);
  return cv + wxv + (wv / (c + 1.0)) * w;
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
