// numerics/pcg.hpp: conjugate gradients preconditioned by another matrix's Cholesky factor solve
// the system to the direct solution's digits; with the matrix's own factor one iteration gives
// the exact solution; an indefinite matrix stops it, not converged; every iterate is a descent
// direction of the quadratic.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "numerics/pcg.hpp"
#include "numerics/sparse_cholesky.hpp"

using namespace yarnhom::numerics;

namespace {

// A 1D Laplacian-like SPD matrix (tridiagonal, diagonal 2 + shift + a ripple), n x n, lower triangle.
Eigen::SparseMatrix<double> chain(int n, double shift, double ripple) {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2 + shift + ripple * std::sin(0.7 * i));
    if (i > 0) t.emplace_back(i, i - 1, -1.0);
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

}  // namespace

TEST(Pcg, ANearbyFactorSolvesTheSystemInAFewIterations) {
  const int n = 200;
  const Eigen::SparseMatrix<double> A = chain(n, 0.05, 0.02);
  const Eigen::SparseMatrix<double> M = chain(n, 0.06, 0.0);  // the lagged matrix
  SparseCholesky fa, fm;
  ASSERT_TRUE(fa.factorize(A));
  ASSERT_TRUE(fm.factorize(M));
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[i] = std::cos(0.3 * i) + 0.1 * i / n;
  const Eigen::VectorXd exact = fa.solve(b);
  int calls = 0;
  const PcgResult r = pcg([&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return A.selfadjointView<Eigen::Lower>() * v; },
                          [&](const Eigen::VectorXd& v) {
                            ++calls;
                            return fm.solve(v);
                          },
                          b, 50, [](const Eigen::VectorXd& x, const Eigen::VectorXd& z) { return z.norm() <= 1e-12 * x.norm(); });
  ASSERT_TRUE(r.converged);
  EXPECT_LE(r.iterations, 12);  // unpreconditioned CG needs far more on this conditioning
  EXPECT_EQ(calls, r.iterations + 1);
  EXPECT_LT((r.x - exact).norm(), 1e-10 * exact.norm());
  // Without the preconditioner (M = I) the same stop is not reached in those iterations.
  const PcgResult plain = pcg([&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return A.selfadjointView<Eigen::Lower>() * v; },
                              [](const Eigen::VectorXd& v) { return v; }, b, r.iterations,
                              [](const Eigen::VectorXd& x, const Eigen::VectorXd& z) { return z.norm() <= 1e-12 * x.norm(); });
  EXPECT_FALSE(plain.converged);
}

TEST(Pcg, TheMatrixsOwnFactorSolvesInOneIteration) {
  const int n = 50;
  const Eigen::SparseMatrix<double> A = chain(n, 0.5, 0.3);
  SparseCholesky fa;
  ASSERT_TRUE(fa.factorize(A));
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1, 2);
  const PcgResult r = pcg([&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return A.selfadjointView<Eigen::Lower>() * v; },
                          [&](const Eigen::VectorXd& v) { return fa.solve(v); }, b, 5,
                          [](const Eigen::VectorXd& x, const Eigen::VectorXd& z) { return z.norm() <= 1e-12 * x.norm(); });
  ASSERT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_LT((r.x - fa.solve(b)).norm(), 1e-12 * b.norm());
}

TEST(Pcg, EveryIterateIsADescentDirectionAndIndefiniteStops) {
  const int n = 100;
  const Eigen::SparseMatrix<double> A = chain(n, 0.01, 0.0);
  Eigen::VectorXd b = Eigen::VectorXd::Ones(n);
  std::vector<double> quad;  // 1/2 x^T A x - b^T x along the iterates
  const PcgResult r = pcg([&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return A.selfadjointView<Eigen::Lower>() * v; },
                          [](const Eigen::VectorXd& v) { return v; }, b, 20,
                          [&](const Eigen::VectorXd& x, const Eigen::VectorXd&) {
                            EXPECT_GT(b.dot(x), 0);
                            quad.push_back(0.5 * x.dot(A.selfadjointView<Eigen::Lower>() * x) - b.dot(x));
                            return false;
                          });
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 20);
  ASSERT_EQ(quad.size(), 20u);
  for (size_t k = 1; k < quad.size(); ++k) EXPECT_LT(quad[k], quad[k - 1]);
  // -A: the first curvature is negative, nothing accepted.
  const PcgResult neg = pcg([&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return -(A.selfadjointView<Eigen::Lower>() * v); },
                            [](const Eigen::VectorXd& v) { return v; }, b, 20,
                            [](const Eigen::VectorXd&, const Eigen::VectorXd&) { return true; });
  EXPECT_FALSE(neg.converged);
  EXPECT_EQ(neg.iterations, 1);
}
