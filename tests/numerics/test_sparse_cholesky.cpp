// The project's sparse Cholesky (numerics/sparse_cholesky.hpp): each of CHOLMOD's orderings
// solves the same system, and the flop count it reports belongs to the ordering asked for.
#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <cstdio>
#include <string>
#include <vector>

#include "numerics/sparse_cholesky.hpp"

using namespace yarnhom::numerics;

namespace {

// The lower triangle of a shifted 9-point Laplacian on an n x n grid (SPD).
Eigen::SparseMatrix<double> grid_matrix(int n) {
  std::vector<Eigen::Triplet<double>> t;
  auto id = [n](int i, int j) { return j * n + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      t.emplace_back(id(i, j), id(i, j), 8.5);
      for (int dj = 0; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          if (dj == 0 && di <= 0) continue;
          const int a = i + di, b = j + dj;
          if (a < 0 || a >= n || b >= n) continue;
          t.emplace_back(id(a, b), id(i, j), -1.0);  // row id(a, b) > column id(i, j)
        }
    }
  Eigen::SparseMatrix<double> A(n * n, n * n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

}  // namespace

TEST(SparseCholesky, EveryOrderingSolvesTheSystemAndCountsItsFlops) {
  if (!cholmod_available()) GTEST_SKIP() << "this build has no CHOLMOD";
  const Eigen::SparseMatrix<double> A = grid_matrix(40);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.rows(), -1, 2);
  const Eigen::SparseMatrix<double> full = A.selfadjointView<Eigen::Lower>();
  double flops[3];
  int k = 0;
  for (Ordering o : {Ordering::Default, Ordering::Metis, Ordering::NestedDissection}) {
    SparseCholesky s(SolverKind::Cholmod, o);
    EXPECT_EQ(s.factor_flops(), 0.0);
    ASSERT_TRUE(s.factorize(A));
    const Eigen::VectorXd x = s.solve(b);
    EXPECT_LT((full * x - b).norm(), 1e-10 * b.norm());
    flops[k] = s.factor_flops();
    EXPECT_GT(flops[k], 0.0);
    EXPECT_GT(s.factor_nonzeros(), double(A.nonZeros()));  // fill-in
    ++k;
  }
  // The orderings differ (the setting reached CHOLMOD): nested dissection's count is not AMD's.
  EXPECT_NE(flops[2], flops[0]);
}

TEST(SparseCholesky, LdltReportsNoFlops) {
  const Eigen::SparseMatrix<double> A = grid_matrix(10);
  SparseCholesky s(SolverKind::Ldlt);
  ASSERT_TRUE(s.factorize(A));
  EXPECT_EQ(s.factor_flops(), 0.0);
  EXPECT_GT(s.factor_nonzeros(), 0.0);
}

// A Newton solver's shift loop fails factorizations often: a matrix that is not positive definite
// is refused (factorize returns false) without a word from CHOLMOD on either stream. (A build
// whose settings missed CHOLMOD printed "CHOLMOD warning: matrix not positive definite" once per
// failed factorization: 259k lines in one 2 x 2 patch dataset's log on 64 ranks.)
TEST(SparseCholesky, AFailedFactorizationIsRefusedSilently) {
  if (!cholmod_available()) GTEST_SKIP() << "this build has no CHOLMOD";
  Eigen::SparseMatrix<double> A = grid_matrix(40);
  A.coeffRef(800, 800) = -50.0;  // one negative pivot in the middle of the grid
  for (Ordering o : {Ordering::Default, Ordering::NestedDissection}) {
    SparseCholesky s(SolverKind::Cholmod, o);
    testing::internal::CaptureStdout();
    testing::internal::CaptureStderr();
    const bool ok = s.factorize(A);
    fflush(stdout);
    const std::string out = testing::internal::GetCapturedStdout();
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_FALSE(ok);
    EXPECT_EQ(out, "");
    EXPECT_EQ(err, "");
  }
}
