#include "sim/second_fundamental_form.hpp"

#include "sim/dihedral_angle.hpp"
#include "sim/edge_height.hpp"
#include "sim/hinge_angles.hpp"

namespace yarnhom::sim {

Eigen::Vector3d second_fundamental_form(const Vec18& q, const Eigen::Matrix3d& Q, const bool has_flap[3],
                                        Eigen::Matrix<double, 3, 18>* J, const Eigen::Vector3d* lambda,
                                        Mat18* H, const double* theta_ref) {
  using Eigen::Vector3d;
  const bool derivs = J || (H && lambda);
  Eigen::Vector3d II = Eigen::Vector3d::Zero();
  if (J) J->setZero();
  const Vector3d x[3] = {q.segment<3>(0), q.segment<3>(3), q.segment<3>(6)};
  for (int i = 0; i < 3; ++i) {
    if (!has_flap[i]) continue;
    const int a = i, b = (i + 1) % 3, c = (i + 2) % 3;
    const Vector3d f = q.segment<3>(9 + 3 * i);
    if (!derivs) {
      double theta = dihedral_angle(x[a], x[b], x[c], f);
      if (theta_ref) theta = unwrap_angle(theta, theta_ref[i]);
      II += theta * edge_height(x[0], x[1], x[2], i) * Q.col(i);
      continue;
    }
    Vec12 gt;
    Mat12 Ht;
    Vec9 gh;
    Mat9 Hh;
    const bool hess = H && lambda;
    double theta = dihedral_angle(x[a], x[b], x[c], f, &gt, hess ? &Ht : nullptr);
    if (theta_ref) theta = unwrap_angle(theta, theta_ref[i]);  // a constant shift: same derivatives
    const double h = edge_height(x[0], x[1], x[2], i, &gh, hess ? &Hh : nullptr);
    II += theta * h * Q.col(i);
    // Element slots of theta's four vertices and of h's three.
    const int st[4] = {a, b, c, 3 + i};
    Vec18 Gt = Vec18::Zero(), Gh = Vec18::Zero();
    for (int k = 0; k < 4; ++k) Gt.segment<3>(3 * st[k]) = gt.segment<3>(3 * k);
    Gh.segment<9>(0) = gh;
    const Vec18 gphi = h * Gt + theta * Gh;
    if (J) *J += Q.col(i) * gphi.transpose();
    if (hess) {
      const double wgt = lambda->dot(Q.col(i));
      if (wgt == 0) continue;
      for (int k = 0; k < 4; ++k)
        for (int m = 0; m < 4; ++m)
          H->block<3, 3>(3 * st[k], 3 * st[m]) += (wgt * h) * Ht.block<3, 3>(3 * k, 3 * m);
      H->block<9, 9>(0, 0) += (wgt * theta) * Hh;
      *H += wgt * (Gt * Gh.transpose() + Gh * Gt.transpose());
    }
  }
  return II;
}

}  // namespace yarnhom::sim
