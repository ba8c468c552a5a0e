// Contact: the kernel is C2 at the cut-off, the pair energy's gradient and Hessian match
// central finite differences, and it is invariant under rigid motions.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "tests/common/yarn_support.hpp"
#include "yarn/rod/contact.hpp"

using namespace yarnhom::yarn;
using yarnhom::yarn::testing::fd_gradient;
using yarnhom::yarn::testing::rel_err;

TEST(Contact, KernelDerivativesAndSmoothCutoff) {
  for (double rho : {0.05, 0.3, 0.7, 0.95}) {
    double d1, d2, d1p, d1m, tmp;
    contact_kernel(rho, &d1, &d2);
    const double h = 1e-6;
    EXPECT_NEAR(d1, (contact_kernel(rho + h) - contact_kernel(rho - h)) / (2 * h), 1e-6 * std::abs(d1) + 1e-9);
    contact_kernel(rho + h, &d1p, &tmp);
    contact_kernel(rho - h, &d1m, &tmp);
    EXPECT_NEAR(d2, (d1p - d1m) / (2 * h), 1e-6 * std::abs(d2) + 1e-8);
  }
  double d1, d2;
  EXPECT_NEAR(contact_kernel(1.0 - 1e-12, &d1, &d2), 0, 1e-30);
  EXPECT_NEAR(d1, 0, 1e-20);
  EXPECT_NEAR(d2, 0, 1e-10);
  EXPECT_EQ(contact_kernel(1.5), 0.0);
}

TEST(Contact, PairGradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> U(-1, 1);
  const ContactParams c{1e-4, 1e6 * 1e-4, 4};
  int touching = 0;
  for (int trial = 0; trial < 30; ++trial) {
    // Two segments of ~3r crossing at a centreline distance in (0.6, 1.6) * 2r.
    const double r = c.radius;
    const Eigen::Vector3d ca(U(rng) * r, U(rng) * r, 0), cb = ca + Eigen::Vector3d(0.3 * U(rng) * r, 0.3 * U(rng) * r, (1.1 + 0.5 * U(rng)) * 2 * r);
    const Eigen::Vector3d da = Eigen::Vector3d(1, 0.3 * U(rng), 0.2 * U(rng)).normalized() * 1.5 * r;
    const Eigen::Vector3d db = Eigen::Vector3d(0.4 * U(rng), 1, 0.2 * U(rng)).normalized() * 1.5 * r;
    Vec12 q;
    q << ca - da, ca + da, cb - db, cb + db;
    Vec12 g;
    Mat12 H;
    const double e = segment_contact_energy(q, 3 * r, 3.2 * r, c, &g, &H);
    if (e == 0) continue;
    ++touching;
    auto E = [&](const Eigen::VectorXd& y) { return segment_contact_energy(y, 3 * r, 3.2 * r, c, nullptr, nullptr); };
    const double h = 1e-9;
    EXPECT_LT(rel_err(g, fd_gradient(E, q, h)), 1e-6) << trial;
    Eigen::MatrixXd Hfd(12, 12);
    for (int i = 0; i < 12; ++i) {
      Vec12 qp = q, qm = q, gp, gm;
      qp[i] += h;
      qm[i] -= h;
      segment_contact_energy(qp, 3 * r, 3.2 * r, c, &gp, nullptr);
      segment_contact_energy(qm, 3 * r, 3.2 * r, c, &gm, nullptr);
      Hfd.col(i) = (gp - gm) / (2 * h);
    }
    EXPECT_LT(rel_err(H, Hfd), 1e-5) << trial;
    // Rigid motion.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(1.0 + trial, Eigen::Vector3d(1, -1, 2).normalized()).toRotationMatrix();
    Vec12 qr;
    for (int k = 0; k < 4; ++k) qr.segment<3>(3 * k) = R * q.segment<3>(3 * k) + Eigen::Vector3d(1e-3, 2e-3, -1e-3);
    EXPECT_NEAR(E(qr), e, 1e-10 * e);
  }
  EXPECT_GT(touching, 10);
}
