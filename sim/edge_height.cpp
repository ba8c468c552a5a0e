#include "sim/edge_height.hpp"

#include <cmath>

#include "numerics/cross_matrix.hpp"

namespace yarnhom::sim {

using numerics::cross_matrix;
using numerics::add_bilinear;

double edge_height(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2, int edge,
                   Vec9* grad, Mat9* hess) {
  using Eigen::Matrix3d;
  using Eigen::Vector3d;
  const Vector3d d1 = x1 - x0, d2 = x2 - x0;
  const Vector3d N = d1.cross(d2);
  const double A = N.norm();
  const Vector3d* xs[3] = {&x0, &x1, &x2};
  const int ia = edge, ib = (edge + 1) % 3;
  const Vector3d ev = *xs[ib] - *xs[ia];
  const double l = ev.norm();
  const double h = A / l;
  if (!grad && !hess) return h;

  const Vector3d Nh = N / A, eh = ev / l;
  const Matrix3d C1 = cross_matrix(d1), C2 = cross_matrix(d2);
  Eigen::Matrix<double, 3, 9> JN;
  JN << C2 - C1, -C2, C1;
  const Vec9 gA = JN.transpose() * Nh;
  Vec9 gl = Vec9::Zero();
  gl.segment<3>(3 * ia) = -eh;
  gl.segment<3>(3 * ib) = eh;
  if (grad) *grad = gA / l - A * gl / (l * l);
  if (!hess) return h;

  const Matrix3d I = Matrix3d::Identity();
  Mat9 HA = JN.transpose() * (I - Nh * Nh.transpose()) * JN / A;
  const double c1[3] = {-1, 1, 0}, c2[3] = {-1, 0, 1};
  add_bilinear<3>(HA, -cross_matrix(Nh), c1, c2);
  const Matrix3d Pl = (I - eh * eh.transpose()) / l;
  Mat9 Hl = Mat9::Zero();
  Hl.block<3, 3>(3 * ia, 3 * ia) = Pl;
  Hl.block<3, 3>(3 * ib, 3 * ib) = Pl;
  Hl.block<3, 3>(3 * ia, 3 * ib) = -Pl;
  Hl.block<3, 3>(3 * ib, 3 * ia) = -Pl;
  *hess = HA / l - (gA * gl.transpose() + gl * gA.transpose()) / (l * l) +
          2 * A * gl * gl.transpose() / (l * l * l) - A * Hl / (l * l);
  return h;
}

}  // namespace yarnhom::sim
