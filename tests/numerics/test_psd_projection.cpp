// numerics/psd_projection.hpp: a PSD matrix is left untouched; an indefinite one keeps its
// eigenvectors, with each negative eigenvalue made 0 (Clamp) or its absolute value (Abs).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "numerics/psd_projection.hpp"

namespace yarnhom::numerics {
namespace {

Eigen::Matrix3d with_eigenvalues(const Eigen::Vector3d& l) {
  const Eigen::Matrix3d Q = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  return Q * l.asDiagonal() * Q.transpose();
}

TEST(PsdProjection, ClampAndAbsFilterTheNegativeEigenvaluesOnly) {
  const Eigen::Matrix3d Q = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  Eigen::Matrix3d H = with_eigenvalues({-2, 1, 3});
  EXPECT_TRUE(project_psd<3>(H));
  EXPECT_LT((H - with_eigenvalues({0, 1, 3})).norm(), 1e-12);
  H = with_eigenvalues({-2, 1, 3});
  EXPECT_TRUE(project_psd<3>(H, EigenFilter::Abs));
  EXPECT_LT((H - with_eigenvalues({2, 1, 3})).norm(), 1e-12);
  EXPECT_LT((H * Q.col(0) - 2 * Q.col(0)).norm(), 1e-12);  // the same eigenvector, curvature 2
  const Eigen::Matrix3d psd = with_eigenvalues({0, 1, 3});
  H = psd;
  EXPECT_FALSE(project_psd<3>(H, EigenFilter::Abs));  // PSD (a zero eigenvalue included): untouched
  EXPECT_EQ(H, psd);
}

// Diagonal pivoting meets a pivot at rounding level (-1e-15) against an off-diagonal 1e-2: the
// next pivot grows to 1e11. The 2 x 2 block's eigenvalues are about +-1e-2 (0.5 % of the
// largest, 2): indefinite, and projected (a check relative to the largest pivot let it through).
TEST(PsdProjection, PivotGrowthIsNotMistakenForDefiniteness) {
  Eigen::Matrix3d H;
  H << 2, 0, 0,
       0, -1e-15, 1e-2,
       0, 1e-2, 0;
  EXPECT_FALSE(nearly_psd<3>(H));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> before(H);
  ASSERT_LT(before.eigenvalues()[0], -9e-3);
  EXPECT_TRUE(project_psd<3>(H));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> after(H);
  EXPECT_GE(after.eigenvalues()[0], -1e-15);
  // A PSD matrix with a rank-deficient block (a zero pivot, as an element's rigid motions give) passes.
  Eigen::Matrix3d P;
  P << 2, 0, 0,
       0, 1, 1,
       0, 1, 1;
  EXPECT_TRUE(nearly_psd<3>(P));
}

}  // namespace
}  // namespace yarnhom::numerics
