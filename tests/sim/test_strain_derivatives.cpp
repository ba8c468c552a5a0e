// Every derivative of the shell's strain against central finite differences in double
// (libshell's discipline): the dihedral angle (gradient and Hessian in 12 coordinates), the
// height over an edge (9), the in-plane strain (9), the second fundamental form (18) and the
// whole strain 6-vector (18), at random generic elements, with and without flaps.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sim/dihedral_angle.hpp"
#include "sim/edge_height.hpp"
#include "sim/element_rest.hpp"
#include "sim/hinge_angles.hpp"
#include "sim/inplane_strain.hpp"
#include "sim/shell_strain.hpp"
#include "tests/common/fd_util.hpp"

using namespace yarnhom::sim;
using yarnhom::Strain6;
using yarnhom::test::fd_gradient;
using yarnhom::test::fd_jacobian;
using yarnhom::test::rel_err;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

// A random bent element: rest triangle of ~1 cm, deformed by a stretch/shear and a bend, flap
// vertices placed across each edge and lifted out of plane.
struct RandomElement {
  ElementRest rest;
  Vec18 q;
};

RandomElement random_element(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  const double L = 0.01;
  Eigen::Vector2d u0(0, 0), u1(L * (1 + 0.3 * U(rng)), L * 0.2 * U(rng)), u2(L * 0.3 * U(rng), L * (1 + 0.3 * U(rng)));
  RandomElement e;
  e.rest = element_rest(u0, u1, u2);
  Eigen::Matrix<double, 3, 2> F;
  F << 1 + 0.3 * U(rng), 0.2 * U(rng), 0.2 * U(rng), 1 + 0.3 * U(rng), 0.1 * U(rng), 0.1 * U(rng);
  const Eigen::Vector2d us[3] = {u0, u1, u2};
  Vector3d x[3];
  for (int i = 0; i < 3; ++i) x[i] = F * us[i] + Vector3d(0, 0, 0.05 * L * U(rng));
  for (int i = 0; i < 3; ++i) e.q.segment<3>(3 * i) = x[i];
  // Flap across edge i: reflect the opposite vertex over the edge's midpoint, lift it.
  for (int i = 0; i < 3; ++i) {
    const Vector3d mid = 0.5 * (x[i] + x[(i + 1) % 3]);
    const Vector3d f = 2 * mid - x[(i + 2) % 3] + L * Vector3d(0.2 * U(rng), 0.2 * U(rng), 0.4 * U(rng));
    e.q.segment<3>(9 + 3 * i) = f;
  }
  return e;
}

}  // namespace

TEST(DihedralAngle, GradientAndHessianMatchFiniteDifferences) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const RandomElement e = random_element(seed);
    VectorXd y(12);
    y << e.q.segment<3>(0), e.q.segment<3>(3), e.q.segment<3>(6), e.q.segment<3>(9);
    auto theta = [](const VectorXd& y) {
      return dihedral_angle(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9));
    };
    Vec12 g;
    Mat12 H;
    const double t = dihedral_angle(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9), &g, &H);
    EXPECT_DOUBLE_EQ(t, theta(y));
    const double h = 1e-7;
    EXPECT_LT(rel_err(g, fd_gradient(theta, y, h)), 1e-6) << "seed " << seed;
    auto grad = [](const VectorXd& y) {
      Vec12 g;
      dihedral_angle(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9), &g);
      return VectorXd(g);
    };
    EXPECT_LT(rel_err(H, fd_jacobian(grad, y, h)), 1e-6) << "seed " << seed;
    EXPECT_LT((H - H.transpose()).cwiseAbs().maxCoeff(), 1e-9 * H.cwiseAbs().maxCoeff());
  }
}

TEST(DihedralAngle, SignAndValueOfAKnownFold) {
  // Main triangle in the plane z = 0 (normal +z), flap across the edge x0 -> x1 (the x axis)
  // folded up by phi towards +z: theta = +phi.
  for (double phi : {0.0, 0.3, -0.7, 1.5, 2.5}) {
    const Vector3d xa(0, 0, 0), xb(1, 0, 0), xc(0.3, 1, 0);
    const Vector3d xd(0.6, -std::cos(phi), std::sin(phi));
    EXPECT_NEAR(dihedral_angle(xa, xb, xc, xd), phi, 1e-14);
  }
}

TEST(EdgeHeight, GradientAndHessianMatchFiniteDifferences) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const RandomElement e = random_element(seed);
    const VectorXd y = e.q.head<9>();
    for (int i = 0; i < 3; ++i) {
      auto h = [i](const VectorXd& y) { return edge_height(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), i); };
      Vec9 g;
      Mat9 H;
      edge_height(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), i, &g, &H);
      EXPECT_LT(rel_err(g, fd_gradient(h, y, 1e-8)), 1e-6);
      auto grad = [i](const VectorXd& y) {
        Vec9 g;
        edge_height(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), i, &g);
        return VectorXd(g);
      };
      EXPECT_LT(rel_err(H, fd_jacobian(grad, y, 1e-8)), 1e-6) << "seed " << seed << " edge " << i;
    }
  }
}

TEST(InplaneStrain, JacobianAndHessiansMatchFiniteDifferences) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const RandomElement e = random_element(seed);
    const VectorXd y = e.q.head<9>();
    const Eigen::Matrix2d B = e.rest.Binv;
    auto s = [&B](const VectorXd& y) {
      return VectorXd(inplane_strain(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), B));
    };
    Eigen::Matrix<double, 3, 9> J;
    inplane_strain(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), B, &J);
    EXPECT_LT(rel_err(J, fd_jacobian(s, y, 1e-8)), 1e-6);
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d lam = Eigen::Vector3d::Unit(k);
      Mat9 H;
      inplane_strain(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), B, nullptr, &lam, &H);
      auto row = [&B, k](const VectorXd& y) {
        Eigen::Matrix<double, 3, 9> J;
        inplane_strain(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), B, &J);
        return VectorXd(J.row(k).transpose());
      };
      EXPECT_LT(rel_err(H, fd_jacobian(row, y, 1e-8)), 1e-6) << "component " << k;
    }
  }
}

// The whole 6-vector: Jacobian rows and each component's Hessian (lambda = unit vectors), with
// all flaps and with some missing (boundary edges).
TEST(ShellStrain, JacobianAndHessiansMatchFiniteDifferences) {
  const bool masks[4][3] = {{true, true, true}, {false, true, true}, {true, false, false}, {false, false, false}};
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const RandomElement e = random_element(seed);
    const bool* fl = masks[seed % 4];
    const VectorXd q = e.q;
    auto s = [&](const VectorXd& y) { return VectorXd(shell_strain(y, e.rest, fl)); };
    Jac6x18 J;
    shell_strain(q, e.rest, fl, &J);
    const MatrixXd Jfd = fd_jacobian(s, q, 1e-8);
    for (int k = 0; k < 6; ++k) {
      EXPECT_LT((J.row(k) - Jfd.row(k)).cwiseAbs().maxCoeff(), 1e-6 * (J.row(k).cwiseAbs().maxCoeff() + 1e-12))
          << "row " << k << " seed " << seed;
      Strain6 lam = Strain6::Unit(k);
      Mat18 H;
      shell_strain(q, e.rest, fl, nullptr, &lam, &H);
      auto row = [&](const VectorXd& y) {
        Jac6x18 J;
        shell_strain(y, e.rest, fl, &J);
        return VectorXd(J.row(k).transpose());
      };
      const MatrixXd Hfd = fd_jacobian(row, q, 1e-8);
      EXPECT_LT((H - Hfd).cwiseAbs().maxCoeff(), 1e-6 * (H.cwiseAbs().maxCoeff() + 1e-12))
          << "component " << k << " seed " << seed;
      EXPECT_LT((H - H.transpose()).cwiseAbs().maxCoeff(), 1e-9 * (H.cwiseAbs().maxCoeff() + 1e-12));
    }
    // Without flaps the bending rows vanish.
    if (!fl[0] && !fl[1] && !fl[2]) {
      EXPECT_EQ(J.bottomRows<3>().cwiseAbs().maxCoeff(), 0.0);
    }
  }
}

// A flap folded past pi: atan2's angle jumps from +pi to -pi and the bending strain with it;
// on the branch carried from the previous position (sim/hinge_angles.hpp) it keeps growing,
// with the same derivatives.
TEST(HingeAngles, FoldPastPiStaysOnTheCarriedBranch) {
  EXPECT_NEAR(unwrap_angle(-3.1, 3.0), 2 * M_PI - 3.1, 1e-15);
  EXPECT_NEAR(unwrap_angle(0.2, 0.1), 0.2, 1e-15);
  EXPECT_NEAR(unwrap_angle(3.1, -3.0), 3.1 - 2 * M_PI, 1e-15);
  const double L = 0.01;
  const ElementRest rest = element_rest({0, 0}, {L, 0}, {0, L});
  const bool fl[3] = {true, false, false};
  auto element = [&](double phi) {  // flap across edge 0 (the x axis) folded up by phi
    Vec18 q = Vec18::Zero();
    q.segment<3>(3) = Vector3d(L, 0, 0);
    q.segment<3>(6) = Vector3d(0, L, 0);
    q.segment<3>(9) = Vector3d(0.5 * L, -L * std::cos(phi), L * std::sin(phi));
    return q;
  };
  const double before = M_PI - 0.01, after = M_PI + 0.01;
  const Strain6 s0 = shell_strain(element(before), rest, fl);
  const Strain6 s_jump = shell_strain(element(after), rest, fl);
  EXPECT_LT(s_jump[5], 0);  // the principal branch flips the curvature's sign
  const double ref[3] = {before, 0, 0};
  Jac6x18 J;
  const Strain6 s1 = shell_strain(element(after), rest, fl, &J, nullptr, nullptr, ref);
  EXPECT_GT(s1[5], s0[5]);  // the carried branch keeps bending further
  EXPECT_NEAR(s1[5] / s0[5], after / before, 1e-12);  // II_y = theta h Q: linear in theta here
  // Its derivatives are those of the carried branch (theta dh uses the unwrapped theta).
  auto f = [&](const VectorXd& y) { return VectorXd(shell_strain(y, rest, fl, nullptr, nullptr, nullptr, ref)); };
  const MatrixXd Jfd = fd_jacobian(f, element(after), 1e-8);
  EXPECT_LT(rel_err(J, Jfd), 1e-6);
}
