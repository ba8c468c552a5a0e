#include "sim/friction.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "numerics/barrier.hpp"

namespace yarnhom::sim {

FrictionMollifier friction_mollifier(double y, double eps) {
  FrictionMollifier m;
  if (y >= eps) {
    // Sliding: f0 = y, f1 = 1, f1' = 0, so the Hessian in u is (I - u u^T/y^2)/y.
    m.f0 = y;
    m.f1_over_y = 1 / y;
    m.uu_coeff = -1 / (y * y * y);
    return m;
  }
  // Sticking (smoothed): f1(y) = 2y/eps - y^2/eps^2, f1'(y) = 2/eps - 2y/eps^2, so
  // f1/y = 2/eps - y/eps^2 and (f1' - f1/y)/y^2 = -1/(eps^2 y): with u u^T it gives
  // -u u^T/(eps^2 y), which is bounded by y/eps^2 and tends to 0 with u.
  m.f0 = -y * y * y / (3 * eps * eps) + y * y / eps + eps / 3;
  m.f1_over_y = 2 / eps - y / (eps * eps);
  m.uu_coeff = y > 0 ? -1 / (eps * eps * y) : 0.0;
  return m;
}

Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& n) {
  // Cross with the coordinate axis least aligned with n: never degenerate.
  Eigen::Index k;
  n.cwiseAbs().minCoeff(&k);
  const Eigen::Vector3d t1 = n.cross(Eigen::Vector3d::Unit(k)).normalized();
  Eigen::Matrix<double, 3, 2> T;
  T.col(0) = t1;
  T.col(1) = n.cross(t1);
  return T;
}

double friction_energy(const FrictionContact& c, const Eigen::Vector3d& xv, double eps, Eigen::Vector3d* grad,
                       Eigen::Matrix3d* hess) {
  const Eigen::Vector2d u = c.T.transpose() * (xv - c.x_start);
  const double y = u.norm();
  const FrictionMollifier m = friction_mollifier(y, eps);
  if (grad) *grad = c.mu_lambda * m.f1_over_y * (c.T * u);
  if (hess) {
    Eigen::Matrix2d Hu = m.f1_over_y * Eigen::Matrix2d::Identity() + m.uu_coeff * u * u.transpose();
    // PSD by construction (header); clamp the eigenvalues so rounding cannot make it indefinite.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(Hu);
    if (es.eigenvalues().minCoeff() < 0)
      Hu = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
    *hess = c.mu_lambda * c.T * Hu * c.T.transpose();
  }
  return c.mu_lambda * m.f0;
}

bool has_friction(const Problem& P) {
  for (const Collider& c : P.colliders)
    if (c.friction > 0) return true;
  return false;
}

std::vector<FrictionContact> friction_contacts(const Problem& P, const std::vector<int>& free_index,
                                               const Eigen::VectorXd& x_at, const Eigen::VectorXd& x_start) {
  std::vector<FrictionContact> out;
  for (size_t ci = 0; ci < P.colliders.size(); ++ci) {
    const Collider& c = P.colliders[ci];
    if (!(c.friction > 0)) continue;
    for (int v = 0; v < P.mesh.num_vertices(); ++v) {
      if (!free_index.empty() && free_index[v] < 0) continue;
      Eigen::Vector3d n;
      const double d = collider_distance(c, x_at.segment<3>(3 * v), &n);
      if (!(d < P.dhat) || !(d > 0)) continue;
      const numerics::BarrierValue b = numerics::distance_barrier(d, P.dhat);
      FrictionContact k;
      k.vertex = v;
      k.collider = int(ci);
      k.mu_lambda = c.friction * P.kappa * P.vertex_area[v] * std::abs(b.db);
      k.T = tangent_basis(n);
      k.x_start = x_start.segment<3>(3 * v);
      if (k.mu_lambda > 0) out.push_back(k);
    }
  }
  return out;
}

}  // namespace yarnhom::sim
