// The shared Newton pieces (numerics/newton.hpp) on small functions with analytic derivatives:
// the Armijo line search on a convex and a nonconvex function (the slope it is given checked
// against finite differences), the growing shift that makes an indefinite matrix factorable
// and its schedule, the step extension, and a full Newton step that solves a quadratic.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <vector>

#include "numerics/newton.hpp"
#include "tests/common/fd_util.hpp"

using namespace yarnhom::numerics;

namespace {

// Lower-triangle triplets of a symmetric matrix.
std::vector<Eigen::Triplet<double>> lower(const Eigen::MatrixXd& A) {
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < A.cols(); ++j)
    for (int i = j; i < A.rows(); ++i)
      if (A(i, j) != 0) t.emplace_back(i, j, A(i, j));
  return t;
}

// Convex: sum_i (exp(x_i) - x_i) + x.A x / 2 with A positive definite.
struct Convex {
  Eigen::MatrixXd A;
  explicit Convex(int n) {
    Eigen::MatrixXd M = Eigen::MatrixXd::Random(n, n);
    A = M * M.transpose() + Eigen::MatrixXd::Identity(n, n);
  }
  double value(const Eigen::VectorXd& x) const { return (x.array().exp() - x.array()).sum() + 0.5 * x.dot(A * x); }
  Eigen::VectorXd grad(const Eigen::VectorXd& x) const { return (x.array().exp() - 1).matrix() + A * x; }
  Eigen::MatrixXd hess(const Eigen::VectorXd& x) const {
    Eigen::MatrixXd H = A;
    H.diagonal() += x.array().exp().matrix();
    return H;
  }
};

// Nonconvex: Rosenbrock's function.
double rosenbrock(const Eigen::VectorXd& x) { return 100 * std::pow(x[1] - x[0] * x[0], 2) + std::pow(1 - x[0], 2); }
Eigen::VectorXd rosenbrock_grad(const Eigen::VectorXd& x) {
  return Eigen::Vector2d(-400 * x[0] * (x[1] - x[0] * x[0]) - 2 * (1 - x[0]), 200 * (x[1] - x[0] * x[0]));
}
Eigen::MatrixXd rosenbrock_hess(const Eigen::VectorXd& x) {
  Eigen::Matrix2d H;
  H << 1200 * x[0] * x[0] - 400 * x[1] + 2, -400 * x[0], -400 * x[0], 200;
  return H;
}

// Armijo at the accepted step and, when it is not the start, not at twice it.
template <class F>
void expect_armijo(const F& f, const Eigen::VectorXd& x, const Eigen::VectorXd& d, double slope, double alpha0,
                   const LineSearchResult& r) {
  const double E = f(x);
  ASSERT_TRUE(r.accepted);
  EXPECT_LE(f(x + r.alpha * d), E + 1e-4 * r.alpha * slope);
  EXPECT_EQ(r.energy, f(x + r.alpha * d));
  if (r.alpha < alpha0) {
    EXPECT_GT(f(x + 2 * r.alpha * d), E + 1e-4 * 2 * r.alpha * slope);
  }
  EXPECT_EQ(r.alpha, alpha0 * std::ldexp(1.0, -(r.trials - 1)));
}

}  // namespace

TEST(Newton, ArmijoLineSearchOnAConvexFunction) {
  const Convex c(6);
  auto f = [&](const Eigen::VectorXd& x) { return c.value(x); };
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(6, -1.0, 1.5);
  // The analytic gradient against central differences, and the slope along d against the
  // derivative of the energy along the line.
  const Eigen::VectorXd g = c.grad(x);
  EXPECT_LT((yarnhom::test::fd_gradient(f, x, 1e-6) - g).norm(), 1e-6 * g.norm());
  const Eigen::VectorXd d = -g;  // steepest descent: a long start step must be shortened
  const double slope = g.dot(d), h = 1e-6;
  EXPECT_NEAR((f(x + h * d) - f(x - h * d)) / (2 * h), slope, 1e-6 * std::abs(slope));
  for (double alpha0 : {1.0, 8.0}) {
    const LineSearchResult r = armijo_backtracking(f(x), slope, alpha0, [&](double a) { return f(x + a * d); });
    expect_armijo(f, x, d, slope, alpha0, r);
    EXPECT_LT(r.energy, f(x));
  }
}

TEST(Newton, ArmijoLineSearchOnANonconvexFunction) {
  const Eigen::VectorXd x = Eigen::Vector2d(-1.2, 1.0);
  // The shifted Newton direction (the Hessian is indefinite here at no shift for some
  // starts; at this one the shift loop still returns a descent direction).
  HessianFactor H(2);
  H.assemble(lower(rosenbrock_hess(x)));
  Eigen::VectorXd d;
  const Eigen::VectorXd g = rosenbrock_grad(x);
  const ShiftResult s = shifted_factorization(0.0, [&](double mu) { return newton_direction(H, mu, g, d); });
  ASSERT_TRUE(s.ok);
  const double slope = g.dot(d), h = 1e-7;
  ASSERT_LT(slope, 0);
  EXPECT_NEAR((rosenbrock(x + h * d) - rosenbrock(x - h * d)) / (2 * h), slope, 1e-5 * std::abs(slope));
  const LineSearchResult r = armijo_backtracking(rosenbrock(x), slope, 1.0, [&](double a) { return rosenbrock(x + a * d); });
  expect_armijo(rosenbrock, x, d, slope, 1.0, r);
  // Steepest descent from a point in the curved valley: many halvings.
  const Eigen::VectorXd y = Eigen::Vector2d(0.5, 0.9), gy = rosenbrock_grad(y);
  const LineSearchResult ry =
      armijo_backtracking(rosenbrock(y), -gy.squaredNorm(), 1.0, [&](double a) { return rosenbrock(y - a * gy); });
  expect_armijo(rosenbrock, y, -gy, -gy.squaredNorm(), 1.0, ry);
  EXPECT_GT(ry.trials, 5);
}

TEST(Newton, LineSearchRejectsNonFiniteEnergiesAndTakesRoundOffSteps) {
  // A barrier: infinite energy beyond alpha = 0.3; the search halves below it.
  auto barrier = [](double a) { return a > 0.3 ? std::numeric_limits<double>::infinity() : -a; };
  const LineSearchResult r = armijo_backtracking(0.0, -1.0, 1.0, barrier);
  ASSERT_TRUE(r.accepted);
  EXPECT_EQ(r.alpha, 0.25);
  EXPECT_EQ(r.trials, 3);
  // A predicted decrease below 1e-13 |E|: energy differences are round-off, the step is taken
  // even when the energy rises; without the round-off rule it is not, and the search gives up
  // after max_trials with the start halved that often.
  auto rising = [](double) { return 1e3 + 1e-6; };
  const LineSearchResult taken = armijo_backtracking(1e3, -1e-12, 1.0, rising);
  EXPECT_TRUE(taken.accepted);
  EXPECT_EQ(taken.alpha, 1.0);
  LineSearchOptions strict;
  strict.roundoff = 0;
  const LineSearchResult refused = armijo_backtracking(1e3, -1e-12, 1.0, rising, strict);
  EXPECT_FALSE(refused.accepted);
  EXPECT_EQ(refused.trials, 40);
  EXPECT_EQ(refused.alpha, std::ldexp(1.0, -40));
}

TEST(Newton, ShiftMakesAnIndefiniteMatrixFactorable) {
  Eigen::MatrixXd A(4, 4);
  A << 4, 1, 0, 0,  //
      1, -2, 1, 0,  //
      0, 1, 3, 1,   //
      0, 0, 1, 0.5;
  ASSERT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues().minCoeff(), 0);
  for (int dense_limit : {HessianFactor::kDenseLimit, 0}) {
    HessianFactor H(4, dense_limit);
    H.assemble(lower(A));
    std::vector<double> tried;
    const ShiftResult s = shifted_factorization(0.0, [&](double mu) {
      tried.push_back(mu);
      return H.factor(mu);
    });
    ASSERT_TRUE(s.ok);
    EXPECT_TRUE(s.plain_failed);
    EXPECT_GT(s.mu, 0);
    EXPECT_EQ(s.attempts, static_cast<int>(tried.size()));
    // 0, 1e-8, 1e-7, ...: the first shift that makes H + mu diag(|H_ii|) positive definite.
    for (size_t k = 1; k < tried.size(); ++k) EXPECT_EQ(tried[k], k == 1 ? 1e-8 : tried[k - 1] * 10);
    auto min_eig = [&](double mu) {
      Eigen::MatrixXd B = A;
      B.diagonal() += mu * A.diagonal().cwiseAbs();
      return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(B).eigenvalues().minCoeff();
    };
    EXPECT_GT(min_eig(s.mu), 0);
    EXPECT_LT(min_eig(s.mu / 10), 0);
    // The shifted system is solved: (A + mu diag) x = b.
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(4, 1, 4);
    Eigen::MatrixXd B = A;
    B.diagonal() += s.mu * A.diagonal().cwiseAbs();
    EXPECT_LT((B * H.solve(b) - b).norm(), 1e-10 * b.norm());
  }
}

TEST(Newton, ShiftScheduleResumesAndGivesUp) {
  std::vector<double> tried;
  auto never = [&](double mu) {
    tried.push_back(mu);
    return false;
  };
  // The RVE's policy: plain Newton first, then the last iteration's shift, growing tenfold.
  ShiftSchedule resume;
  resume.resume = 0.5;
  resume.max_attempts = 4;
  ShiftResult s = shifted_factorization(0.0, never, resume);
  EXPECT_FALSE(s.ok);
  EXPECT_TRUE(s.plain_failed);
  EXPECT_EQ(tried, (std::vector<double>{0.0, 0.5, 5.0, 50.0}));
  // The simulator's: 12 more tries after the unshifted one, 1e-8 x 10^k.
  tried.clear();
  ShiftSchedule sim;
  sim.max_attempts = 13;
  s = shifted_factorization(0.0, never, sim);
  ASSERT_EQ(tried.size(), 13u);
  EXPECT_EQ(tried[1], 1e-8);
  EXPECT_DOUBLE_EQ(tried[12], 1e3);
  EXPECT_EQ(s.mu, tried.back());
  // A start that is already shifted never goes back to 0.
  tried.clear();
  s = shifted_factorization(1e-3, [&](double mu) {
    tried.push_back(mu);
    return mu >= 0.1;
  });
  EXPECT_TRUE(s.ok);
  EXPECT_FALSE(s.plain_failed);
  EXPECT_EQ(tried.size(), 3u);
  EXPECT_EQ(relaxed_shift(s.mu), s.mu / 10);
  EXPECT_EQ(relaxed_shift(9e-8), 0.0);
  EXPECT_EQ(raised_shift(1e-8), 1e-3);
  EXPECT_EQ(raised_shift(0.1), 10.0);
}

TEST(Newton, StepExtensionDoublesWhileTheEnergyFalls) {
  // Along the line the energy is (alpha - 5)^2: from the accepted full step, 2 and 4 lower
  // it, 8 does not.
  auto f = [](double a) { return (a - 5) * (a - 5); };
  std::vector<double> taken;
  const Extension x = extend_step(1.0, f(1.0), -10.0, 12, 0.0, f, [&](double a) { taken.push_back(a); });
  EXPECT_EQ(x.alpha, 4.0);
  EXPECT_EQ(x.energy, 1.0);
  EXPECT_EQ(x.doublings, 2);
  EXPECT_EQ(taken, (std::vector<double>{2.0, 4.0}));
  // At most max_doublings; a disallowed move (non-finite) stops it; a sufficient decrease
  // c alpha slope is required when c > 0.
  EXPECT_EQ(extend_step(1.0, f(1.0), -10.0, 1, 0.0, f).alpha, 2.0);
  auto walled = [&](double a) { return a > 3 ? std::numeric_limits<double>::quiet_NaN() : f(a); };
  EXPECT_EQ(extend_step(1.0, f(1.0), -10.0, 12, 0.0, walled).alpha, 2.0);
  EXPECT_EQ(extend_step(1.0, f(1.0), -10.0, 12, 0.5, f).alpha, 2.0);  // 4: 1 > 9 - 0.5 * 2 * 10
}

TEST(Newton, FullNewtonStepSolvesAQuadratic) {
  // E = x.A x / 2 - b.x: one shifted-factorization step with mu = 0 and the line search's
  // full step land on A^-1 b.
  const int n = 8;
  Eigen::MatrixXd M = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd A = M * M.transpose() + Eigen::MatrixXd::Identity(n, n);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1, 2);
  auto E = [&](const Eigen::VectorXd& x) { return 0.5 * x.dot(A * x) - b.dot(x); };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n), d;
  const Eigen::VectorXd g = A * x - b;
  const Eigen::VectorXd scale = Eigen::VectorXd::Ones(n);
  EXPECT_GT(relative_residual(g, scale, 1.0), 0.1);
  HessianFactor H(n);
  H.assemble(lower(A));
  const ShiftResult s = shifted_factorization(0.0, [&](double mu) { return newton_direction(H, mu, g, d); });
  ASSERT_TRUE(s.ok);
  EXPECT_EQ(s.mu, 0.0);
  EXPECT_EQ(s.attempts, 1);
  const LineSearchResult r = armijo_backtracking(E(x), g.dot(d), 1.0, [&](double a) { return E(x + a * d); });
  ASSERT_TRUE(r.accepted);
  EXPECT_EQ(r.alpha, 1.0);
  // A quadratic model that is exact gains half its slope: no extension criterion would fire.
  EXPECT_NEAR(r.energy - E(x), 0.5 * g.dot(d), 1e-12 * std::abs(g.dot(d)));
  x += r.alpha * d;
  EXPECT_LT(relative_residual(A * x - b, scale, 1.0), 1e-12);
  EXPECT_LT((x - A.ldlt().solve(b)).norm(), 1e-12 * x.norm());
  EXPECT_EQ(relative_residual(Eigen::VectorXd(), Eigen::VectorXd(), 1.0), 0.0);
}

TEST(Newton, StatusNamesAndReport) {
  EXPECT_STREQ(to_string(SolveStatus::kConverged), "converged");
  EXPECT_STREQ(to_string(SolveStatus::kInfeasibleStart), "infeasible_start");
  EXPECT_STREQ(to_string(SolveStatus::kTimeLimit), "time_limit");
  NewtonReport rep;
  EXPECT_FALSE(rep.converged());
  rep.status = SolveStatus::kConverged;
  EXPECT_TRUE(rep.converged());
}
