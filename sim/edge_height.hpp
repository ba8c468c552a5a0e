#pragma once
// The height of a triangle over one of its edges, h_i = |N| / l_i (N = (x1 - x0) x (x2 - x0),
// l_i = |x_{i+1} - x_i|), with exact gradient and Hessian in (x0, x1, x2). It is the factor
// 2a/l_i with which the dihedral angle enters the second fundamental form.
//
// |N|: grad = J_N^T N^,  Hess = J_N^T (I - N^ N^^T) J_N / |N| + d2(N^ . (d1 x d2)), with
// J_N = [[d2]x - [d1]x, -[d2]x, [d1]x] and N^ . (d1 x d2) = d1^T (-[N^]x) d2.
// l: grad +-e^, Hess blocks +-(I - e^ e^^T)/l. Then h = A/l by the quotient rule:
//   dh = dA/l - A dl/l^2,
//   d2h = d2A/l - (dA dl^T + dl dA^T)/l^2 + 2A dl dl^T/l^3 - A d2l/l^2.
#include "sim/inplane_strain.hpp"

namespace yarnhom::sim {

double edge_height(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2, int edge,
                   Vec9* grad = nullptr, Mat9* hess = nullptr);

}  // namespace yarnhom::sim
