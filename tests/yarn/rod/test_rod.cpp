// Discrete elastic rod terms: gradient and Hessian of stretch, bend and twist against central
// finite differences in double, at random joints with non-trivial frame transport; invariance
// under rigid motions; the re-basing of frames leaves the energy unchanged.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "tests/common/yarn_support.hpp"
#include "yarn/rod/rod.hpp"

using namespace yarnhom::yarn;
using yarnhom::yarn::testing::fd_gradient;
using yarnhom::yarn::testing::rel_err;

namespace {

struct RandomJoint {
  Vec11 q;
  JointFrames f;
  JointRest rest;
};

RandomJoint random_joint(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  const double L = 1e-3;
  RandomJoint j;
  const Eigen::Vector3d xv(U(rng) * L, U(rng) * L, U(rng) * L);
  const Eigen::Vector3d ein = Eigen::Vector3d(1, 0.3 * U(rng), 0.3 * U(rng)).normalized() * L * (1 + 0.2 * U(rng));
  const Eigen::Vector3d eout = Eigen::Vector3d(1, 0.6 * U(rng), 0.6 * U(rng)).normalized() * L * (1 + 0.2 * U(rng));
  j.q << xv - ein, xv, xv + eout, U(rng), U(rng);
  // Stored frames at tangents a little different from the current ones.
  auto frame = [&](const Eigen::Vector3d& e) {
    const Eigen::Vector3d t = (e.normalized() + 0.1 * Eigen::Vector3d(U(rng), U(rng), U(rng))).normalized();
    Eigen::Vector3d d(U(rng), U(rng), U(rng));
    d = (d - d.dot(t) * t).normalized();
    return EdgeFrame{t, d};
  };
  j.f = {frame(ein), frame(eout), 0.0};
  const Vec11 q = j.q;
  j.f.twist_hint = joint_strain(q, j.f).twist - (q[10] - q[9]);  // current branch
  j.rest.kappa = Eigen::Vector2d(0.3 * U(rng), 0.3 * U(rng));
  j.rest.twist = 0.2 * U(rng);
  j.rest.voronoi = L;
  return j;
}

// Step sizes: positions ~1e-3 m get 1e-8 m, angles get 1e-6 rad.
Eigen::VectorXd steps11() {
  Eigen::VectorXd h(11);
  h.head<9>().setConstant(1e-8);
  h.tail<2>().setConstant(1e-6);
  return h;
}

template <class F>
Eigen::VectorXd fd_grad_steps(F f, Eigen::VectorXd x, const Eigen::VectorXd& h) {
  Eigen::VectorXd g(x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += h[i];
    xm[i] -= h[i];
    g[i] = (f(xp) - f(xm)) / (2 * h[i]);
  }
  return g;
}

void check_joint_term(int terms) {
  std::mt19937 rng(7 + terms);
  const double EI = 1e6 * M_PI * 1e-12 / 4, GJ = 3e5 * M_PI * 1e-12 / 2;
  for (int trial = 0; trial < 20; ++trial) {
    const RandomJoint j = random_joint(rng);
    Vec11 g;
    Mat11 H;
    joint_energy(j.q, j.f, j.rest, EI, GJ, terms, &g, &H);
    auto E = [&](const Eigen::VectorXd& q) { return joint_energy(q, j.f, j.rest, EI, GJ, terms, nullptr, nullptr); };
    const Eigen::VectorXd gfd = fd_grad_steps(E, j.q, steps11());
    EXPECT_LT(rel_err(g, gfd), 1e-6) << "gradient, trial " << trial;
    Eigen::MatrixXd Hfd(11, 11);
    const Eigen::VectorXd h = steps11();
    for (int i = 0; i < 11; ++i) {
      Vec11 qp = j.q, qm = j.q, gp, gm;
      qp[i] += h[i];
      qm[i] -= h[i];
      joint_energy(qp, j.f, j.rest, EI, GJ, terms, &gp, nullptr);
      joint_energy(qm, j.f, j.rest, EI, GJ, terms, &gm, nullptr);
      Hfd.col(i) = (gp - gm) / (2 * h[i]);
    }
    EXPECT_LT(rel_err(H, Hfd), 1e-5) << "Hessian, trial " << trial;
    EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm());
  }
}

}  // namespace

TEST(Rod, StretchGradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  const double EA = 1e6 * M_PI * 1e-8;
  for (int trial = 0; trial < 20; ++trial) {
    Vec6 x;
    for (int i = 0; i < 6; ++i) x[i] = 1e-3 * U(rng);
    const double L = 1e-3 * (1 + 0.5 * U(rng));
    Vec6 g;
    Mat6 H;
    stretch_energy(x.head<3>(), x.tail<3>(), L, EA, &g, &H);
    auto E = [&](const Eigen::VectorXd& y) {
      return stretch_energy(y.head<3>(), y.tail<3>(), L, EA, nullptr, nullptr);
    };
    EXPECT_LT(rel_err(g, fd_gradient(E, x, 1e-9)), 1e-6);
    Eigen::MatrixXd Hfd(6, 6);
    for (int i = 0; i < 6; ++i) {
      Vec6 xp = x, xm = x, gp, gm;
      xp[i] += 1e-9;
      xm[i] -= 1e-9;
      stretch_energy(xp.head<3>(), xp.tail<3>(), L, EA, &gp, nullptr);
      stretch_energy(xm.head<3>(), xm.tail<3>(), L, EA, &gm, nullptr);
      Hfd.col(i) = (gp - gm) / 2e-9;
    }
    EXPECT_LT(rel_err(H, Hfd), 1e-6);
  }
}

TEST(Rod, BendGradientAndHessianMatchFiniteDifferences) { check_joint_term(kBend); }
TEST(Rod, TwistGradientAndHessianMatchFiniteDifferences) { check_joint_term(kTwist); }

TEST(Rod, EnergiesInvariantUnderRigidMotion) {
  std::mt19937 rng(11);
  const double EI = 1e6 * M_PI * 1e-12 / 4, GJ = 3e5 * M_PI * 1e-12 / 2;
  for (int trial = 0; trial < 10; ++trial) {
    const RandomJoint j = random_joint(rng);
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(0.7 + trial, Eigen::Vector3d(1, 2, 3 - trial).normalized()).toRotationMatrix();
    const Eigen::Vector3d c(1e-3, -2e-3, 5e-4);
    Vec11 q = j.q;
    for (int k = 0; k < 3; ++k) q.segment<3>(3 * k) = R * j.q.segment<3>(3 * k) + c;
    JointFrames f = j.f;  // frames move with the rod
    f.in = {R * j.f.in.t, R * j.f.in.d1};
    f.out = {R * j.f.out.t, R * j.f.out.d1};
    for (int terms : {kBend, kTwist}) {
      const double e0 = joint_energy(j.q, j.f, j.rest, EI, GJ, terms, nullptr, nullptr);
      const double e1 = joint_energy(q, f, j.rest, EI, GJ, terms, nullptr, nullptr);
      EXPECT_NEAR(e1, e0, 1e-10 * std::abs(e0) + 1e-25);
    }
    const double s0 = stretch_energy(j.q.segment<3>(0), j.q.segment<3>(3), 9e-4, 1.0, nullptr, nullptr);
    const double s1 = stretch_energy(q.segment<3>(0), q.segment<3>(3), 9e-4, 1.0, nullptr, nullptr);
    EXPECT_NEAR(s1, s0, 1e-12 * s0);
  }
}

TEST(Rod, RebasingFramesLeavesEnergyUnchanged) {
  std::mt19937 rng(5);
  const double EI = 1.0, GJ = 0.7;
  for (int trial = 0; trial < 10; ++trial) {
    const RandomJoint j = random_joint(rng);
    const double e0 = joint_energy(j.q, j.f, j.rest, EI, GJ, kBendTwist, nullptr, nullptr);
    const Eigen::Vector3d tin = (j.q.segment<3>(3) - j.q.segment<3>(0)).normalized();
    const Eigen::Vector3d tout = (j.q.segment<3>(6) - j.q.segment<3>(3)).normalized();
    JointFrames f;
    f.in = {tin, transported_director(j.f.in, tin)};
    f.out = {tout, transported_director(j.f.out, tout)};
    f.twist_hint = reference_twist(f.in.t, f.in.d1, f.out.t, f.out.d1, j.f.twist_hint);
    const double e1 = joint_energy(j.q, f, j.rest, EI, GJ, kBendTwist, nullptr, nullptr);
    EXPECT_NEAR(e1, e0, 1e-12 * std::abs(e0));
  }
}

TEST(Rod, StraightUntwistedRodHasZeroEnergyAndTwistMeasuresTheta) {
  Vec11 q;
  q << 0, 0, 0, 1, 0, 0, 2, 0, 0, 0.1, 0.4;
  JointFrames f{{Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()}, {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()}, 0};
  const JointStrain s = joint_strain(q, f);
  EXPECT_NEAR(s.k1, 0, 1e-15);
  EXPECT_NEAR(s.k2, 0, 1e-15);
  EXPECT_NEAR(s.twist, 0.3, 1e-15);
  // A bend in the x-y plane by angle a has |kb| = 2 tan(a/2), along +z.
  const double a = 0.5;
  q.segment<3>(6) = Eigen::Vector3d(1 + std::cos(a), std::sin(a), 0);
  q[9] = q[10] = 0;
  f.out = {Eigen::Vector3d(std::cos(a), std::sin(a), 0), Eigen::Vector3d(-std::sin(a), std::cos(a), 0)};
  const JointStrain b = joint_strain(q, f);
  EXPECT_NEAR(std::hypot(b.k1, b.k2), 2 * std::tan(a / 2), 1e-12);
  EXPECT_NEAR(b.twist, 0, 1e-12);
}
