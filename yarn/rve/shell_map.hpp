#pragma once
// The macroscopic shell map of a strain s (spec section 2 and 4, docs/rve.md):
//
//   phi(xi) = (F xi, 1/2 xi^T II xi)            (mid-surface; F = [[a, b], [0, c]] with
//                                                F^T F = I(s), upper triangular: no rotation)
//   Phi(xi, h) = phi(xi) + h n(xi)               (a point at height h over the mid-surface)
//   R(xi) = [q1, q2, n],  [q1 q2] = A (A^T A)^{-1/2},  A = [phi_,1 phi_,2]
//
// R is the rotation of the polar decomposition of the surface tangent map at xi: the local
// mid-surface frame in which fluctuations are expressed. At s = 0, Phi is the identity and
// R = I. Templated on the scalar so that dx/ds (for the envelope theorem) comes exactly from
// forward differentiation (Jet<6>).
#include <Eigen/Core>

#include "material/strain.hpp"
#include "numerics/jet.hpp"

namespace yarnhom::yarn {

using numerics::Jet;
using numerics::V3;

using Strain = Strain6;  // material/strain.hpp

template <class T>
struct ShellPoint {
  V3<T> p;       // Phi(xi, h)
  V3<T> R[3];    // columns q1, q2, n
  V3<T> apply(const Eigen::Vector3d& u) const { return p + (u[0] * R[0] + u[1] * R[1] + u[2] * R[2]); }
};

// s = [s_x, s_a, s_y, II_x, II_a, II_y] as scalars of type T (double or Jet<6>).
template <class T>
ShellPoint<T> shell_map(const T s[6], double xi1, double xi2, double h) {
  using std::sqrt;
  const T a = 1.0 + s[0], c0 = 1.0 + s[2];
  const T b = s[1] * c0;                       // I01 / a
  const T c = c0 * sqrt(1.0 - s[1] * s[1]);    // sqrt(I11 - b^2)
  const T k1 = s[3] * xi1 + s[4] * xi2;        // (II xi)_1
  const T k2 = s[4] * xi1 + s[5] * xi2;        // (II xi)_2
  const V3<T> phi(a * xi1 + b * xi2, c * xi2, 0.5 * (xi1 * k1 + xi2 * k2));
  const V3<T> A1(a, T(0.0), k1), A2(b, c, k2);  // phi_,1 and phi_,2
  // (A^T A)^{-1/2} of the 2x2 SPD metric M: sqrt(M) = (M + sqrt(det) I) / sqrt(tr + 2 sqrt(det)).
  const T m11 = dot(A1, A1), m12 = dot(A1, A2), m22 = dot(A2, A2);
  const T sd = sqrt(m11 * m22 - m12 * m12);
  const T tn = sqrt(m11 + m22 + 2.0 * sd);
  const T r11 = (m11 + sd) / tn, r12 = m12 / tn, r22 = (m22 + sd) / tn;  // sqrt(M)
  const T rdet = r11 * r22 - r12 * r12;
  const T i11 = r22 / rdet, i12 = -r12 / rdet, i22 = r11 / rdet;         // sqrt(M)^-1
  ShellPoint<T> out;
  out.R[0] = i11 * A1 + i12 * A2;
  out.R[1] = i12 * A1 + i22 * A2;
  out.R[2] = cross(out.R[0], out.R[1]);
  out.p = phi + h * out.R[2];
  return out;
}

}  // namespace yarnhom::yarn
