// The Newton system's factorization (numerics/hessian_factor.hpp): the dense and the sparse path
// solve the same shifted system from lower-triangle triplets, and both refuse a matrix that is
// not positive definite until the shift makes it so.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <vector>

#include "numerics/hessian_factor.hpp"

using yarnhom::numerics::HessianFactor;

namespace {

// Lower-triangle triplets of A, with every off-diagonal entry split in two (duplicates are
// summed, as the RVE's assembly relies on).
std::vector<Eigen::Triplet<double>> lower_triplets(const Eigen::MatrixXd& A) {
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < A.cols(); ++j)
    for (int i = j; i < A.rows(); ++i) {
      if (A(i, j) == 0) continue;
      if (i == j) {
        t.emplace_back(i, j, A(i, j));
      } else {
        t.emplace_back(i, j, 0.25 * A(i, j));
        t.emplace_back(i, j, 0.75 * A(i, j));
      }
    }
  return t;
}

}  // namespace

TEST(HessianFactor, DenseAndSparsePathsSolveTheShiftedSystem) {
  const int n = 40;
  Eigen::MatrixXd M = Eigen::MatrixXd::Random(n, n);
  Eigen::MatrixXd A = M * M.transpose() + n * Eigen::MatrixXd::Identity(n, n);  // SPD
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if ((i + 2 * j) % 5 == 0 && i != j) A(i, j) = A(j, i) = 0;  // some sparsity, still SPD
  A += n * Eigen::MatrixXd::Identity(n, n);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
  for (double mu : {0.0, 0.3}) {
    Eigen::MatrixXd As = A;
    As.diagonal() += mu * A.diagonal().cwiseAbs();
    const Eigen::VectorXd x = As.ldlt().solve(b);
    for (int limit : {HessianFactor::kDenseLimit, 0}) {
      HessianFactor H(n, limit);
      EXPECT_EQ(H.dense(), limit > 0);
      H.assemble(lower_triplets(A));
      ASSERT_TRUE(H.factor(mu)) << "dense " << H.dense() << " mu " << mu;
      EXPECT_LT((H.solve(b) - x).norm(), 1e-12 * x.norm()) << "dense " << H.dense() << " mu " << mu;
    }
  }
}

TEST(HessianFactor, IndefiniteMatrixIsRefusedUntilShifted) {
  const int n = 6;
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n);
  A(2, 2) = -0.5;  // one negative eigenvalue; |A_22| = 0.5, so mu > 1 makes it 0.5 (mu - 1) > 0
  A(3, 1) = A(1, 3) = 0.1;
  for (int limit : {HessianFactor::kDenseLimit, 0}) {
    HessianFactor H(n, limit);
    H.assemble(lower_triplets(A));
    EXPECT_FALSE(H.factor(0.0)) << "dense " << H.dense();
    EXPECT_FALSE(H.factor(0.5)) << "dense " << H.dense();
    EXPECT_TRUE(H.factor(2.0)) << "dense " << H.dense();
    Eigen::MatrixXd As = A;
    As.diagonal() += 2.0 * A.diagonal().cwiseAbs();
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1, 2);
    EXPECT_LT((H.solve(b) - As.ldlt().solve(b)).norm(), 1e-13) << "dense " << H.dense();
  }
}
