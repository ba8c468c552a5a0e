#pragma once
// In-plane strain of one triangle (spec sections 2 and 10), with exact derivatives in the
// triangle's 9 coordinates (x0, x1, x2):
//
//   F = [x1 - x0, x2 - x0] Dm^-1,   f1 = F e1,  f2 = F e2,
//   s_x = |f1| - 1,   s_a = f1.f2 / (|f1| |f2|),   s_y = |f2| - 1.
//
// f_a = sum_v c_av x_v is linear in the vertices (c_a = (-(B0a + B1a), B0a, B1a), B = Dm^-1),
// so everything is first done in (f1, f2) and then mapped. With a = |f1|, b = |f2|,
// u = f1/a, w = f2/b, c = u.w (= s_a), P_u = I - u u^T:
//   ds_x/df1 = u,                         d2s_x/df1^2 = P_u / a
//   ds_a/df1 = g1 = (w - c u)/a,          ds_a/df2 = g2 = (u - c w)/b
//   d2s_a/df1^2 = -(u g1^T + g1 u^T)/a - c P_u / a^2
//   d2s_a/df1 df2 = (P_w / b - u g2^T)/a  (= (d2s_a/df2 df1)^T)
// and the same with the roles of f1 and f2 swapped for s_y and d2s_a/df2^2.
//
// project_psd: the contracted Hessian is first formed in (f1, f2), a 6 x 6 matrix; projecting
// that onto the positive semi-definite cone before mapping it to the vertices gives a PSD 9 x 9
// matrix (a congruence C^T P C of a PSD P) for a 6 x 6 eigenproblem instead of a 9 x 9 or
// 18 x 18 one, equal to the exact term whenever the 6 x 6 one is already PSD (e.g. both
// directions in tension with little shear: lambda_x, lambda_y > 0 and lambda_a small). The 6 x 6
// matrix splits into a 4 x 4 block in the triangle's plane and a 2 x 2 block along its normal
// (inplane_strain.cpp), projected apart: the same projection, for a 4 x 4 and a closed-form
// 2 x 2 eigenproblem (the whole 6 x 6 one only for a triangle sheared flat).
#include <Eigen/Core>

#include "numerics/psd_projection.hpp"

namespace yarnhom::sim {

using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;

// s = (s_x, s_a, s_y). J (if given) = ds/dx (3 x 9). H (if given) = sum_k lambda_k d2s_k/dx2.
Eigen::Vector3d inplane_strain(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                               const Eigen::Matrix2d& Binv, Eigen::Matrix<double, 3, 9>* J = nullptr,
                               const Eigen::Vector3d* lambda = nullptr, Mat9* H = nullptr, bool project_psd = false,
                               numerics::EigenFilter filter = numerics::EigenFilter::Clamp);

}  // namespace yarnhom::sim
