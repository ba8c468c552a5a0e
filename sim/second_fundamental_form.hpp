#pragma once
// The discrete second fundamental form of one triangle, pulled back to material coordinates
// (HYLC's per-triangle shape operator, spec section 10), with exact derivatives in the
// element's 18 coordinates q = (x0, x1, x2, f0, f1, f2), f_i the flap vertex across edge i
// (x_i -> x_{i+1}):
//
//   II = sum_i phi_i Q_i,   phi_i = theta_i h_i      (sim/element_rest.hpp says why)
//
// theta_i the signed dihedral angle across edge i (sim/dihedral_angle.hpp), h_i the height
// over edge i (sim/edge_height.hpp); a boundary edge (no flap) contributes nothing. By the
// product rule, dphi = h dtheta + theta dh and
//   d2phi = h d2theta + theta d2h + dtheta dh^T + dh dtheta^T.
// Components are returned as (II_x, II_a, II_y) = (II00, II01, II11).
//
// theta_ref (3 angles, optional): the branch of each dihedral angle. atan2 gives theta in
// (-pi, pi], which jumps by 2 pi when a flap folds past its neighbour (a free edge of a soft,
// curling knit does that on a coarse mesh): the energy jumps there and a line search stalls on
// the wall. With a reference, theta is the value nearest theta_ref, continuous in q
// (sim/hinge_angles.hpp keeps the references from step to step).
#include <Eigen/Core>

namespace yarnhom::sim {

using Vec18 = Eigen::Matrix<double, 18, 1>;
using Mat18 = Eigen::Matrix<double, 18, 18>;

// J (if given) = dII/dq (3 x 18). H (if given, with lambda) += sum_k lambda_k d2II_k/dq2.
Eigen::Vector3d second_fundamental_form(const Vec18& q, const Eigen::Matrix3d& Q, const bool has_flap[3],
                                        Eigen::Matrix<double, 3, 18>* J = nullptr,
                                        const Eigen::Vector3d* lambda = nullptr, Mat18* H = nullptr,
                                        const double* theta_ref = nullptr);

}  // namespace yarnhom::sim
