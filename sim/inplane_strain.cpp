#include "sim/inplane_strain.hpp"

#include <cmath>

#include "numerics/psd_projection.hpp"

namespace yarnhom::sim {

namespace {

// The PSD projection of the 6 x 6 contracted Hessian [H11 H12; H12^T H22] in (f1, f2), split by
// its structure. With n the triangle's normal (u x w normalized), every block maps n to a
// multiple of n and the tangent plane into itself: P_u n = P_w n = n and u, w, g1, g2 lie in
// the plane. So in the basis (e1, e2, n) of each of f1, f2 (e1 = u, e2 = the in-plane unit
// normal to u) the matrix is a 4 x 4 tangent block plus a 2 x 2 normal block
//   N = [lx/a - la c/a^2, la/(a b); la/(a b), ly/b - la c/b^2],
// each projected on its own: the same projection as the 6 x 6 eigenproblem's up to rounding, at
// a fraction of its cost. Returns 1 when a block was projected, 0 when nothing was negative (the
// blocks untouched), -1 when the triangle is sheared flat (u parallel to w: the caller projects
// the 6 x 6 matrix).
int project_split(Eigen::Matrix3d& H11, Eigen::Matrix3d& H12, Eigen::Matrix3d& H22, const Eigen::Vector3d& u,
                  const Eigen::Vector3d& w, double a, double b, double cs, double lx, double la, double ly,
                  numerics::EigenFilter filter) {
  const Eigen::Vector3d t = w - cs * u;
  const double sn = t.norm();
  if (!(sn > 1e-6)) return -1;
  Eigen::Matrix<double, 3, 2> E;
  E.col(0) = u;
  E.col(1) = t / sn;
  const Eigen::Vector3d n = u.cross(E.col(1));
  Eigen::Matrix4d T;
  T.block<2, 2>(0, 0) = E.transpose() * H11 * E;
  T.block<2, 2>(0, 2) = E.transpose() * H12 * E;
  T.block<2, 2>(2, 0) = T.block<2, 2>(0, 2).transpose();
  T.block<2, 2>(2, 2) = E.transpose() * H22 * E;
  T = (0.5 * (T + T.transpose())).eval();
  Eigen::Matrix2d N;
  N << lx / a - la * cs / (a * a), la / (a * b), la / (a * b), ly / b - la * cs / (b * b);
  const bool tc = numerics::project_psd<4>(T, filter), nc = numerics::project_psd<2>(N, filter);
  if (!tc && !nc) return 0;
  const Eigen::Matrix3d nn = n * n.transpose();
  H11 = E * T.block<2, 2>(0, 0) * E.transpose() + N(0, 0) * nn;
  H12 = E * T.block<2, 2>(0, 2) * E.transpose() + N(0, 1) * nn;
  H22 = E * T.block<2, 2>(2, 2) * E.transpose() + N(1, 1) * nn;
  return 1;
}

}  // namespace

Eigen::Vector3d inplane_strain(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                               const Eigen::Matrix2d& B, Eigen::Matrix<double, 3, 9>* J,
                               const Eigen::Vector3d* lambda, Mat9* H, bool psd, numerics::EigenFilter filter) {
  // c(a, v): coefficient of vertex v in f_a.
  double c[2][3];
  for (int a = 0; a < 2; ++a) {
    c[a][1] = B(0, a);
    c[a][2] = B(1, a);
    c[a][0] = -(B(0, a) + B(1, a));
  }
  const Eigen::Vector3d d1 = x1 - x0, d2 = x2 - x0;
  const Eigen::Vector3d f1 = d1 * B(0, 0) + d2 * B(1, 0), f2 = d1 * B(0, 1) + d2 * B(1, 1);
  const double a = f1.norm(), b = f2.norm();
  const Eigen::Vector3d u = f1 / a, w = f2 / b;
  const double cs = u.dot(w);
  const Eigen::Vector3d s(a - 1.0, cs, b - 1.0);
  if (!J && !H) return s;
  // Gradient in f = (f1, f2): rows s_x, s_a, s_y.
  const Eigen::Vector3d g1 = (w - cs * u) / a, g2 = (u - cs * w) / b;
  Eigen::Matrix<double, 3, 6> G = Eigen::Matrix<double, 3, 6>::Zero();
  G.block<1, 3>(0, 0) = u.transpose();
  G.block<1, 3>(1, 0) = g1.transpose();
  G.block<1, 3>(1, 3) = g2.transpose();
  G.block<1, 3>(2, 3) = w.transpose();
  if (J)
    for (int v = 0; v < 3; ++v)
      J->block<3, 3>(0, 3 * v) = c[0][v] * G.block<3, 3>(0, 0) + c[1][v] * G.block<3, 3>(0, 3);
  if (H && lambda) {
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d Pu = I - u * u.transpose(), Pw = I - w * w.transpose();
    const double lx = (*lambda)[0], la = (*lambda)[1], ly = (*lambda)[2];
    // Contracted Hessian in f, blocks [f1 f1, f1 f2; f2 f1, f2 f2].
    Eigen::Matrix3d H11 = lx * Pu / a + la * (-(u * g1.transpose() + g1 * u.transpose()) / a - cs * Pu / (a * a));
    Eigen::Matrix3d H22 = ly * Pw / b + la * (-(w * g2.transpose() + g2 * w.transpose()) / b - cs * Pw / (b * b));
    Eigen::Matrix3d H12 = la * (Pw / b - u * g2.transpose()) / a;
    if (psd && project_split(H11, H12, H22, u, w, a, b, cs, lx, la, ly, filter) < 0) {
      Eigen::Matrix<double, 6, 6> Hf;
      Hf << H11, H12, H12.transpose(), H22;
      Hf = (0.5 * (Hf + Hf.transpose())).eval();  // H11, H22 symmetric up to rounding
      if (numerics::project_psd(Hf, filter)) {
        H11 = Hf.block<3, 3>(0, 0);
        H12 = Hf.block<3, 3>(0, 3);
        H22 = Hf.block<3, 3>(3, 3);
      }
    }
    for (int v = 0; v < 3; ++v)
      for (int q = 0; q < 3; ++q)
        H->block<3, 3>(3 * v, 3 * q) = c[0][v] * c[0][q] * H11 + c[1][v] * c[1][q] * H22 +
                                       c[0][v] * c[1][q] * H12 + c[1][v] * c[0][q] * H12.transpose();
  }
  return s;
}

}  // namespace yarnhom::sim
