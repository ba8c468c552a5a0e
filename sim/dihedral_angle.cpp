#include "sim/dihedral_angle.hpp"

#include <cmath>

#include "numerics/cross_matrix.hpp"

namespace yarnhom::sim {

using numerics::cross_matrix;
using numerics::add_bilinear;

double dihedral_angle(const Eigen::Vector3d& xa, const Eigen::Vector3d& xb, const Eigen::Vector3d& xc,
                      const Eigen::Vector3d& xd, Vec12* grad, Mat12* hess) {
  using Eigen::Matrix3d;
  using Eigen::Vector3d;
  const Vector3d e = xb - xa, g = xc - xa, p = xd - xa;
  const Vector3d w = e.cross(g);  // main triangle normal
  const Vector3d v = p.cross(e);  // flap normal
  const double le = e.norm();
  const double vw = v.dot(w);
  const double T = e.dot(v.cross(w)), C = le * vw;
  const double theta = std::atan2(T, C);
  if (!grad && !hess) return theta;

  const double R = T * T + C * C;
  const double tT = C / R, tC = -T / R;
  const Vector3d ah = e / le;
  Eigen::Matrix<double, 9, 1> dT, dC;
  dT << w.cross(e), e.cross(v), v.cross(w);
  dC << le * w, le * v, vw * ah;
  const Eigen::Matrix<double, 9, 1> mu = tT * dT + tC * dC;  // dtheta/dz, z = (v, w, a)

  // Jacobian of z in y = (xa, xb, xc, xd).
  //   v = p x e:  dv/dxd = -[e]x, dv/dxb = [p]x, dv/dxa = [e]x - [p]x
  //   w = e x g:  dw/dxb = -[g]x, dw/dxc = [e]x, dw/dxa = [g]x - [e]x
  //   a = e:      da/dxb = I, da/dxa = -I
  const Matrix3d E = cross_matrix(e), P = cross_matrix(p), G = cross_matrix(g), I = Matrix3d::Identity();
  Eigen::Matrix<double, 9, 12> Jz = Eigen::Matrix<double, 9, 12>::Zero();
  Jz.block<3, 3>(0, 0) = E - P;
  Jz.block<3, 3>(0, 3) = P;
  Jz.block<3, 3>(0, 9) = -E;
  Jz.block<3, 3>(3, 0) = G - E;
  Jz.block<3, 3>(3, 3) = -G;
  Jz.block<3, 3>(3, 6) = E;
  Jz.block<3, 3>(6, 0) = -I;
  Jz.block<3, 3>(6, 3) = I;
  if (grad) *grad = Jz.transpose() * mu;
  if (!hess) return theta;

  const double R2 = R * R;
  const double tTT = -2 * T * C / R2, tCC = 2 * T * C / R2, tTC = (T * T - C * C) / R2;
  Eigen::Matrix<double, 9, 9> Hz = tTT * dT * dT.transpose() + tCC * dC * dC.transpose() +
                                   tTC * (dT * dC.transpose() + dC * dT.transpose());
  // tT d2T
  const Matrix3d A = cross_matrix(e), W = cross_matrix(w), V = cross_matrix(v);
  Hz.block<3, 3>(0, 3) += -tT * A;
  Hz.block<3, 3>(3, 0) += tT * A;
  Hz.block<3, 3>(0, 6) += tT * W;
  Hz.block<3, 3>(6, 0) += -tT * W;
  Hz.block<3, 3>(3, 6) += -tT * V;
  Hz.block<3, 3>(6, 3) += tT * V;
  // tC d2C
  Hz.block<3, 3>(0, 3) += tC * le * I;
  Hz.block<3, 3>(3, 0) += tC * le * I;
  Hz.block<3, 3>(0, 6) += tC * w * ah.transpose();
  Hz.block<3, 3>(6, 0) += tC * ah * w.transpose();
  Hz.block<3, 3>(3, 6) += tC * v * ah.transpose();
  Hz.block<3, 3>(6, 3) += tC * ah * v.transpose();
  Hz.block<3, 3>(6, 6) += tC * vw * (I - ah * ah.transpose()) / le;

  *hess = Jz.transpose() * Hz * Jz;
  // mu_v . (p x e) = p^T (-[mu_v]x) e with p = xd - xa, e = xb - xa;
  // mu_w . (e x g) = e^T (-[mu_w]x) g with e = xb - xa, g = xc - xa.
  const double cp[4] = {-1, 0, 0, 1}, ce[4] = {-1, 1, 0, 0}, cg[4] = {-1, 0, 1, 0};
  add_bilinear<4>(*hess, -cross_matrix(mu.segment<3>(0)), cp, ce);
  add_bilinear<4>(*hess, -cross_matrix(mu.segment<3>(3)), ce, cg);
  return theta;
}

}  // namespace yarnhom::sim
