#pragma once
// The signed dihedral angle across one edge of the shell, with its exact gradient and Hessian
// in the 12 coordinates of the four vertices involved.
//
// xa -> xb is the edge as the main triangle (xa, xb, xc) runs through it (counterclockwise),
// xd the flap vertex on the other side. With e = xb - xa:
//   w = e x (xc - xa)   the main triangle's normal (length twice its area)
//   v = (xd - xa) x e   the flap triangle's normal, oriented consistently
//   theta = atan2(T, C),  T = e . (v x w),  C = |e| (v . w)
// Both normals are perpendicular to e for every position, so T = |e||v||w| sin(theta) and
// C = |e||v||w| cos(theta): theta is the angle from the main triangle's normal to the flap's,
// positive when the flap bends towards the main triangle's normal n (the surface curves
// towards n, which makes II positive: spec section 2's sign, as in the yarn producer's
// shell map). 0 when flat.
//
// Derivatives go through z = (v, w, a = e) (9 numbers):
//   dT/dv = w x a,  dT/da = v x w,  dT/dw = a x v;
//   d2T: (v,w) -[a]x, (v,a) [w]x, (w,a) -[v]x (and transposes), diagonal blocks 0
//   dC/dv = |a| w,  dC/dw = |a| v,  dC/da = (v.w) a^;
//   d2C: (v,w) |a| I, (v,a) w a^T, (w,a) v a^T, (a,a) (v.w)(I - a a^T)/|a|
//   dtheta = (C dT - T dC)/R, R = T^2 + C^2; d2theta/dT2 = -2TC/R^2, d2theta/dC2 = 2TC/R^2,
//   d2theta/dTdC = (T^2 - C^2)/R^2.
// then to positions: theta_y = J^T theta_z, theta_yy = J^T theta_zz J + the second derivatives
// of the bilinear maps v(p, e), w(e, g) weighted by theta_v, theta_w.
#include <Eigen/Core>

namespace yarnhom::sim {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

// Coordinates ordered (xa, xb, xc, xd).
double dihedral_angle(const Eigen::Vector3d& xa, const Eigen::Vector3d& xb, const Eigen::Vector3d& xc,
                      const Eigen::Vector3d& xd, Vec12* grad = nullptr, Mat12* hess = nullptr);

}  // namespace yarnhom::sim
