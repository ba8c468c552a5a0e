#pragma once
// What one triangle keeps from its rest shape: Dm^-1, the rest area, and the three constant
// 2x2 matrices through which the dihedral angles enter the second fundamental form.
//
// Why II is linear in theta_i h_i (our derivation of spec section 10's formula). With m_i the
// deformed triangle's unit outward in-plane normal of edge i, h_i = 2a/l_i its height over
// that edge, and D = [x1 - x0, x2 - x0] (so F = D Dm^-1):
//   D^T m_i = h_i eps_i,  eps_0 = (0, -1), eps_1 = (1, 1), eps_2 = (-1, 0)
// because m_i is perpendicular to edge i and the opposite vertex lies h_i inside. Hence
// F^T m_i = h_i Dm^-T eps_i and
//   II = sum_i theta_i l_i/(2a) (F^T m_i)(F^T m_i)^T = sum_i theta_i h_i Q_i,
//   Q_i = (Dm^-T eps_i)(Dm^-T eps_i)^T,
// a rest quantity. Derivatives of II are those of the three scalars theta_i h_i.
#include <Eigen/Core>

namespace yarnhom::sim {

struct ElementRest {
  Eigen::Matrix2d Binv;  // Dm^-1
  double area = 0;       // rest area A_T
  Eigen::Matrix3d Q;     // column i: (Q_i00, Q_i01, Q_i11) of edge i
};

// u0, u1, u2 counterclockwise (positive area).
ElementRest element_rest(const Eigen::Vector2d& u0, const Eigen::Vector2d& u1, const Eigen::Vector2d& u2);

}  // namespace yarnhom::sim
