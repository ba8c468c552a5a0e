// The Newton system's factorization (numerics/hessian_factor.hpp): the dense and the sparse path
// solve the same shifted system from lower-triangle triplets, and both refuse a matrix that is
// not positive definite until the shift makes it so.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdlib>
#include <utility>
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

namespace {

// B (sparse SPD, banded with a few far couplings) and the RVE's kind of low-rank term: U = [a h]
// with a dense over every third unknown, h sparse, C = [[c, 1], [1, 0]] (one eigenvalue of each
// sign).
struct LowRankCase {
  Eigen::MatrixXd B, U, C;
  Eigen::MatrixXd whole() const { return B + U * C * U.transpose(); }
};

LowRankCase low_rank_case(int n, double c, unsigned seed) {
  std::srand(seed);
  LowRankCase k;
  k.B = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    k.B(i, i) = 4.0 + 0.1 * i / n;
    if (i + 1 < n) k.B(i, i + 1) = k.B(i + 1, i) = -1.0;
    if (i + 7 < n && i % 5 == 0) k.B(i, i + 7) = k.B(i + 7, i) = 0.5;
  }
  k.U = Eigen::MatrixXd::Zero(n, 2);
  for (int i = 0; i < n; i += 3) k.U(i, 0) = 0.3 * (1.0 + Eigen::VectorXd::Random(1)[0]);
  for (int i = 0; i < 4; ++i) k.U(2 * i + 1, 1) = Eigen::VectorXd::Random(1)[0];
  k.C.resize(2, 2);
  k.C << c, 1, 1, 0;
  return k;
}

}  // namespace

TEST(HessianFactor, LowRankTermSolvesLikeTheExplicitMatrixOnBothPaths) {
  const int n = 60;
  for (double c : {2.0, 0.0, -0.5}) {
    const LowRankCase k = low_rank_case(n, c, 7);
    const Eigen::MatrixXd A = k.whole();
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1, 2);
    for (double mu : {0.0, 0.05}) {
      Eigen::MatrixXd As = A;
      As.diagonal() += mu * A.diagonal().cwiseAbs();
      const Eigen::LLT<Eigen::MatrixXd> ref(As);
      ASSERT_EQ(ref.info(), Eigen::Success) << "c " << c << " mu " << mu;
      const Eigen::VectorXd x = ref.solve(b);
      for (int limit : {HessianFactor::kDenseLimit, 0})
        for (bool stable : {false, true}) {
          HessianFactor H(n, limit, stable);
          H.assemble(lower_triplets(k.B), k.U, k.C);
          ASSERT_TRUE(H.factor(mu)) << "dense " << H.dense() << " c " << c << " mu " << mu;
          EXPECT_LT((H.solve(b) - x).norm(), 1e-12 * x.norm()) << "dense " << H.dense() << " c " << c << " mu " << mu;
        }
    }
  }
}

TEST(HessianFactor, LowRankTermThatMakesTheWholeIndefiniteIsRefused) {
  // B is positive definite; U C U^T = a h^T + h a^T with h = -a pushes one eigenvalue below
  // zero (a^T (B - 2 a a^T) a < 0 for |a| large): the sparse path must see it through the 2 x 2
  // test, not from B's factorization, which succeeds.
  const int n = 30;
  LowRankCase k = low_rank_case(n, 0.0, 3);
  k.U.col(0).setConstant(1.0);
  k.U.col(1) = -k.U.col(0);
  ASSERT_EQ(Eigen::LLT<Eigen::MatrixXd>(k.B).info(), Eigen::Success);
  ASSERT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(k.whole()).eigenvalues().minCoeff(), 0.0);
  for (int limit : {HessianFactor::kDenseLimit, 0}) {
    HessianFactor H(n, limit, true);
    H.assemble(lower_triplets(k.B), k.U, k.C);
    EXPECT_FALSE(H.factor(0.0)) << "dense " << H.dense();
    // A shift large enough makes the whole definite again, on both paths alike.
    double mu = 1e-3;
    while (!H.factor(mu) && mu < 1e6) mu *= 10;
    Eigen::MatrixXd As = k.whole();
    As.diagonal() += mu * k.whole().diagonal().cwiseAbs();
    EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(As).info(), Eigen::Success) << "dense " << H.dense() << " mu " << mu;
    Eigen::MatrixXd Aless = k.whole();
    Aless.diagonal() += 0.1 * mu * k.whole().diagonal().cwiseAbs();
    EXPECT_NE(Eigen::LLT<Eigen::MatrixXd>(Aless).info(), Eigen::Success) << "dense " << H.dense() << " mu " << mu;
  }
}

TEST(HessianFactor, StablePatternGrowsAndReusesItsAnalysis) {
  const int n = 40;
  const Eigen::MatrixXd A = low_rank_case(n, 0.0, 5).B;
  Eigen::MatrixXd A2 = A;
  A2(30, 2) = A2(2, 30) = 0.7;  // an entry A lacks (a new contact pair)
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1, 3);
  HessianFactor H(n, 0, true);
  int analyses = 0;
  for (const auto& [M, grows] : {std::pair{A, true}, {A, false}, {A2, true}, {A, false}, {A2, false}}) {
    H.assemble(lower_triplets(M));
    ASSERT_TRUE(H.factor(0.0));
    analyses += grows ? 1 : 0;
    EXPECT_EQ(H.analyses(), analyses) << "a pattern covered by the earlier ones is not analysed again";
    const Eigen::VectorXd x = M.llt().solve(b);
    EXPECT_LT((H.solve(b) - x).norm(), 1e-12 * x.norm()) << "the zeros the pattern keeps change nothing";
  }
}
