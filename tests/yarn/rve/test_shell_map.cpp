// The shell map reproduces the strain: F^T F = I(s) and phi_,ab . n = II_ab at the centre; it
// is the identity at s = 0; R is a rotation; its strain derivative (forward mode) matches
// finite differences.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "numerics/jet.hpp"
#include "yarn/rve/shell_map.hpp"

using namespace yarnhom::yarn;
using namespace yarnhom::numerics;

namespace {
Eigen::Vector3d P(const Strain& s, double x1, double x2, double h) {
  const auto sp = shell_map(s.data(), x1, x2, h);
  return {sp.p.x, sp.p.y, sp.p.z};
}
Eigen::Matrix3d Rm(const Strain& s, double x1, double x2) {
  const auto sp = shell_map(s.data(), x1, x2, 0.0);
  Eigen::Matrix3d R;
  for (int c = 0; c < 3; ++c) R.col(c) << sp.R[c].x, sp.R[c].y, sp.R[c].z;
  return R;
}
}  // namespace

TEST(ShellMap, FundamentalFormsAtTheCentre) {
  Strain s;
  s << 0.3, -0.4, 0.1, 120, -40, 80;
  const double h = 1e-5;
  const Eigen::Vector3d p1 = (P(s, h, 0, 0) - P(s, -h, 0, 0)) / (2 * h);
  const Eigen::Vector3d p2 = (P(s, 0, h, 0) - P(s, 0, -h, 0)) / (2 * h);
  EXPECT_NEAR(p1.dot(p1), std::pow(1 + s[0], 2), 1e-9);
  EXPECT_NEAR(p2.dot(p2), std::pow(1 + s[2], 2), 1e-9);
  EXPECT_NEAR(p1.dot(p2), s[1] * (1 + s[0]) * (1 + s[2]), 1e-9);
  const Eigen::Vector3d n = p1.cross(p2).normalized();
  const Eigen::Vector3d p0 = P(s, 0, 0, 0);
  const Eigen::Vector3d p11 = (P(s, h, 0, 0) - 2 * p0 + P(s, -h, 0, 0)) / (h * h);
  const Eigen::Vector3d p22 = (P(s, 0, h, 0) - 2 * p0 + P(s, 0, -h, 0)) / (h * h);
  const Eigen::Vector3d p12 = (P(s, h, h, 0) - P(s, h, -h, 0) - P(s, -h, h, 0) + P(s, -h, -h, 0)) / (4 * h * h);
  EXPECT_NEAR(p11.dot(n), s[3], 1e-3);
  EXPECT_NEAR(p12.dot(n), s[4], 1e-3);
  EXPECT_NEAR(p22.dot(n), s[5], 1e-3);
  // Normal offset: the point at height h lies along the normal.
  EXPECT_NEAR((P(s, 0, 0, 1e-3) - p0 - 1e-3 * n).norm(), 0, 1e-15);
}

TEST(ShellMap, IdentityAtRestAndRotationEverywhere) {
  const Strain z = Strain::Zero();
  EXPECT_NEAR((P(z, 1e-3, -2e-3, 5e-4) - Eigen::Vector3d(1e-3, -2e-3, 5e-4)).norm(), 0, 1e-18);
  EXPECT_NEAR((Rm(z, 1e-3, 2e-3) - Eigen::Matrix3d::Identity()).norm(), 0, 1e-15);
  Strain s;
  s << -0.2, 0.6, 0.9, -200, 150, 230;
  const Eigen::Matrix3d R = Rm(s, 4e-3, -3e-3);
  EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0, 1e-14);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
}

TEST(ShellMap, StrainDerivativeMatchesFiniteDifferences) {
  Strain s;
  s << 0.2, 0.3, -0.1, 90, -30, 60;
  const double x1 = 3e-3, x2 = -2e-3, h = 4e-4;
  const Eigen::Vector3d u(1e-4, -2e-4, 3e-4);
  Jet<6> sj[6];
  for (int k = 0; k < 6; ++k) sj[k] = Jet<6>::variable(k, s[k]);
  const V3<Jet<6>> xj = shell_map(sj, x1, x2, h).apply(u);
  for (int k = 0; k < 6; ++k) {
    const double step = k < 3 ? 1e-6 : 1e-3;
    Strain sp = s, sm = s;
    sp[k] += step;
    sm[k] -= step;
    const auto a = shell_map(sp.data(), x1, x2, h).apply(u), b = shell_map(sm.data(), x1, x2, h).apply(u);
    const Eigen::Vector3d fd((a.x - b.x) / (2 * step), (a.y - b.y) / (2 * step), (a.z - b.z) / (2 * step));
    const Eigen::Vector3d ad(xj.x.g[k], xj.y.g[k], xj.z.g[k]);
    EXPECT_LT((ad - fd).norm(), 1e-7 * (ad.norm() + 1e-9)) << "component " << k;
  }
}
