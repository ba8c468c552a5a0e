#pragma once
// Second-order forward-mode differentiation: a Jet<N> carries a value, its gradient and its
// Hessian with respect to N inputs. The rod stencils are written once as templates on the
// scalar type; instantiated with double they give the energy, with Jet<N> its exact gradient
// and Hessian (exact up to round-off, no truncation error). Hand-derived discrete-elastic-rod
// Hessians are long and easy to get subtly wrong (the reference-twist terms especially); this
// removes that class of bug, and the tests still check every term against finite differences.
#include <Eigen/Core>
#include <cmath>

namespace yarnhom::numerics {

template <int N>
struct Jet {
  double v = 0.0;
  Eigen::Matrix<double, N, 1> g = Eigen::Matrix<double, N, 1>::Zero();
  Eigen::Matrix<double, N, N> h = Eigen::Matrix<double, N, N>::Zero();

  Jet() = default;
  Jet(double value) : v(value) {}  // NOLINT: constants promote implicitly
  // The i-th independent variable with value x.
  static Jet variable(int i, double x) {
    Jet j(x);
    j.g[i] = 1.0;
    return j;
  }
};

// Applies a scalar function with derivatives f1 = f'(a), f2 = f''(a): the chain rule.
template <int N>
inline Jet<N> chain(const Jet<N>& a, double f0, double f1, double f2) {
  Jet<N> r;
  r.v = f0;
  r.g = f1 * a.g;
  r.h = f1 * a.h + f2 * (a.g * a.g.transpose());
  return r;
}

template <int N> inline Jet<N> operator+(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> r; r.v = a.v + b.v; r.g = a.g + b.g; r.h = a.h + b.h; return r;
}
template <int N> inline Jet<N> operator-(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> r; r.v = a.v - b.v; r.g = a.g - b.g; r.h = a.h - b.h; return r;
}
template <int N> inline Jet<N> operator-(const Jet<N>& a) {
  Jet<N> r; r.v = -a.v; r.g = -a.g; r.h = -a.h; return r;
}
template <int N> inline Jet<N> operator*(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> r;
  r.v = a.v * b.v;
  r.g = a.v * b.g + b.v * a.g;
  const Eigen::Matrix<double, N, N> outer = a.g * b.g.transpose();
  r.h = a.v * b.h + b.v * a.h + outer + outer.transpose();
  return r;
}
template <int N> inline Jet<N> operator/(const Jet<N>& a, const Jet<N>& b) {
  const double ib = 1.0 / b.v;
  return a * chain(b, ib, -ib * ib, 2.0 * ib * ib * ib);
}
template <int N> inline Jet<N> operator+(const Jet<N>& a, double b) { Jet<N> r = a; r.v += b; return r; }
template <int N> inline Jet<N> operator+(double b, const Jet<N>& a) { return a + b; }
template <int N> inline Jet<N> operator-(const Jet<N>& a, double b) { Jet<N> r = a; r.v -= b; return r; }
template <int N> inline Jet<N> operator-(double b, const Jet<N>& a) { return -a + b; }
template <int N> inline Jet<N> operator*(const Jet<N>& a, double b) {
  Jet<N> r; r.v = a.v * b; r.g = a.g * b; r.h = a.h * b; return r;
}
template <int N> inline Jet<N> operator*(double b, const Jet<N>& a) { return a * b; }
template <int N> inline Jet<N> operator/(const Jet<N>& a, double b) { return a * (1.0 / b); }
template <int N> inline Jet<N> operator/(double a, const Jet<N>& b) {
  const double ib = 1.0 / b.v;
  return chain(b, a * ib, -a * ib * ib, 2.0 * a * ib * ib * ib);
}

template <int N> inline Jet<N> sqrt(const Jet<N>& a) {
  const double s = std::sqrt(a.v);
  return chain(a, s, 0.5 / s, -0.25 / (s * a.v));
}
template <int N> inline Jet<N> sin(const Jet<N>& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return chain(a, s, c, -s);
}
template <int N> inline Jet<N> cos(const Jet<N>& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return chain(a, c, -s, -c);
}
// atan2(y, x) with its two-argument chain rule.
template <int N> inline Jet<N> atan2(const Jet<N>& y, const Jet<N>& x) {
  const double r2 = x.v * x.v + y.v * y.v, r4 = r2 * r2;
  const double fx = -y.v / r2, fy = x.v / r2;
  const double fxx = 2 * x.v * y.v / r4, fyy = -fxx, fxy = (y.v * y.v - x.v * x.v) / r4;
  Jet<N> r;
  r.v = std::atan2(y.v, x.v);
  r.g = fx * x.g + fy * y.g;
  const Eigen::Matrix<double, N, N> xy = x.g * y.g.transpose();
  r.h = fx * x.h + fy * y.h + fxx * (x.g * x.g.transpose()) + fyy * (y.g * y.g.transpose()) +
        fxy * (xy + xy.transpose());
  return r;
}

inline double value(double a) { return a; }
template <int N> inline double value(const Jet<N>& a) { return a.v; }

// A 3-vector over any scalar (Eigen matrices of a custom scalar need NumTraits plumbing that
// is not worth it for the handful of operations the rods use).
template <class T>
struct V3 {
  T x, y, z;
  V3() = default;
  V3(T a, T b, T c) : x(a), y(b), z(c) {}
  explicit V3(const Eigen::Vector3d& a) : x(a[0]), y(a[1]), z(a[2]) {}
};
template <class T> inline V3<T> operator+(const V3<T>& a, const V3<T>& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
template <class T> inline V3<T> operator-(const V3<T>& a, const V3<T>& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
template <class T, class S> inline V3<T> operator*(const S& s, const V3<T>& a) { return {a.x * s, a.y * s, a.z * s}; }
template <class T> inline T dot(const V3<T>& a, const V3<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T> inline V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T> inline T norm(const V3<T>& a) { using std::sqrt; return sqrt(dot(a, a)); }

}  // namespace yarnhom::numerics
