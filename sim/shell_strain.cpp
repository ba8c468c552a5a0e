#include "sim/shell_strain.hpp"

#include "sim/inplane_strain.hpp"

namespace yarnhom::sim {

Strain6 shell_strain(const Vec18& q, const ElementRest& rest, const bool has_flap[3], Jac6x18* J,
                     const Strain6* lambda, Mat18* H, const double* theta_ref) {
  Strain6 s;
  Eigen::Matrix<double, 3, 9> Jin;
  Eigen::Matrix<double, 3, 18> Jb;
  Mat9 Hin;
  const bool hess = H && lambda;
  Eigen::Vector3d lin, lb;
  if (hess) {
    lin = lambda->head<3>();
    lb = lambda->tail<3>();
    H->setZero();
  }
  s.head<3>() = inplane_strain(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), rest.Binv, J ? &Jin : nullptr,
                               hess ? &lin : nullptr, hess ? &Hin : nullptr);
  s.tail<3>() = second_fundamental_form(q, rest.Q, has_flap, J ? &Jb : nullptr, hess ? &lb : nullptr, H, theta_ref);
  if (J) {
    J->setZero();
    J->block<3, 9>(0, 0) = Jin;
    J->block<3, 18>(3, 0) = Jb;
  }
  if (hess) H->block<9, 9>(0, 0) += Hin;
  return s;
}

}  // namespace yarnhom::sim
