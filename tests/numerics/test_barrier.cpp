// The log barrier: C2 at the activation distance, infinite at the minimum separation, and the
// pair energy's exact gradient and Hessian against central finite differences for every
// distance type and for nearly parallel segments.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "numerics/barrier.hpp"

using namespace yarnhom::numerics;

namespace {
// |a - b| / |b| (Frobenius), b floored.
double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor = 1e-300) {
  return (a - b).norm() / std::max(b.norm(), floor);
}
}  // namespace

TEST(Barrier, DerivativesAndSmoothActivation) {
  for (double z : {1e-6, 1e-3, 0.05, 0.3, 0.7, 0.99}) {
    double d1, d2, d1p, d1m, t;
    barrier(z, &d1, &d2);
    const double h = 1e-7 * z;
    EXPECT_NEAR(d1, (barrier(z + h) - barrier(z - h)) / (2 * h), 1e-6 * std::abs(d1) + 1e-12) << z;
    barrier(z + h, &d1p, &t);
    barrier(z - h, &d1m, &t);
    EXPECT_NEAR(d2, (d1p - d1m) / (2 * h), 1e-5 * std::abs(d2) + 1e-10) << z;
    EXPECT_GT(barrier(z), 0.0);
    EXPECT_LT(d1, 0.0) << "repulsive";
  }
  // Value, slope and curvature all vanish at z = 1 (C2), and b is exactly 0 beyond.
  double d1, d2;
  const double b = barrier(1.0 - 1e-6, &d1, &d2);
  EXPECT_LT(b, 1e-17);
  EXPECT_LT(std::abs(d1), 1e-11);
  EXPECT_LT(std::abs(d2), 1e-5);
  EXPECT_EQ(barrier(1.0), 0.0);
  EXPECT_EQ(barrier(2.0), 0.0);
  EXPECT_TRUE(std::isinf(barrier(0.0)));
  EXPECT_TRUE(std::isinf(barrier(-0.1)));
  EXPECT_GT(barrier(1e-12), barrier(1e-6));
}

// The continuum simulator's form of the same barrier, dhat b(d / dhat) in a distance d: its
// closed form (IPC's -(d - dhat)^2 ln(d / dhat) / dhat), derivatives against central finite
// differences in d, zero beyond dhat and infinite at contact.
TEST(Barrier, DistanceFormMatchesItsClosedFormAndFiniteDifferences) {
  const double dhat = 2e-3;
  for (double d : {1e-7, 1e-5, 3e-4, 1e-3, 1.9e-3}) {
    const BarrierValue v = distance_barrier(d, dhat);
    const double e = d - dhat, L = std::log(d / dhat);
    EXPECT_NEAR(v.b, -e * e * L / dhat, 1e-12 * std::abs(v.b) + 1e-300) << d;
    const double h = 1e-6 * d;
    const BarrierValue p = distance_barrier(d + h, dhat), m = distance_barrier(d - h, dhat);
    EXPECT_NEAR(v.db, (p.b - m.b) / (2 * h), 1e-6 * std::abs(v.db)) << d;
    EXPECT_NEAR(v.d2b, (p.db - m.db) / (2 * h), 1e-5 * std::abs(v.d2b)) << d;
    EXPECT_LT(v.db, 0.0) << "repulsive";
  }
  const BarrierValue far = distance_barrier(dhat, dhat);
  EXPECT_EQ(far.b, 0.0);
  EXPECT_EQ(far.db, 0.0);
  EXPECT_EQ(far.d2b, 0.0);
  EXPECT_TRUE(std::isinf(distance_barrier(0.0, dhat).b));
  EXPECT_TRUE(std::isinf(distance_barrier(-1e-4, dhat).b));
}

TEST(Barrier, PairEnergyGradientAndHessianMatchFiniteDifferences) {
  // Random pairs of ~unit segments within the activation distance, all types.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  const BarrierParams p{0.1, 0.6, 2.5};
  int checked[9] = {0}, total = 0;
  for (int trial = 0; trial < 20000 && total < 9 * 6; ++trial) {
    const Vec12 q = Vec12::NullaryExpr([&](Eigen::Index) { return U(rng); });
    const ClosestPair cp = closest_pair(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
    const double d = segment_distance(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
    auto inside = [](double x) { return x == 0 || x == 1 || (x > 0.05 && x < 0.95); };
    if (!(d > 0.15 && d < 0.55) || !inside(cp.s) || !inside(cp.t)) continue;
    const int k = static_cast<int>(cp.type);
    if (checked[k] >= 6) continue;
    ++checked[k];
    ++total;
    Vec12 g;
    Mat12 H;
    const double e = segment_barrier_energy(q, p, &g, &H);
    ASSERT_GT(e, 0);
    const double h = 1e-7;
    Vec12 gfd;
    Mat12 Hfd;
    for (int i = 0; i < 12; ++i) {
      Vec12 qp = q, qm = q, gp, gm;
      qp[i] += h;
      qm[i] -= h;
      gfd[i] = (segment_barrier_energy(qp, p, &gp) - segment_barrier_energy(qm, p, &gm)) / (2 * h);
      Hfd.col(i) = (gp - gm) / (2 * h);
    }
    EXPECT_LT(rel_err(g, gfd), 1e-6) << to_string(cp.type);
    EXPECT_LT(rel_err(H, Hfd), 1e-5) << to_string(cp.type);
  }
  for (int k = 0; k < 9; ++k) EXPECT_EQ(checked[k], 6) << to_string(SegmentDistanceType(k));
}

TEST(Barrier, NearlyParallelPairDerivatives) {
  const BarrierParams p{0.1, 0.6, 1.0};
  for (double angle : {0.05, 3e-3}) {
    const Eigen::Vector3d dir(std::cos(angle), std::sin(angle), 0);
    Vec12 q;
    q << 0, 0, 0, 1, 0, 0, Eigen::Vector3d(0.5, 0, 0.3) - 0.4 * dir, Eigen::Vector3d(0.5, 0, 0.3) + 0.4 * dir;
    Vec12 g;
    Mat12 H;
    segment_barrier_energy(q, p, &g, &H);
    const double h = 1e-7;
    Vec12 gfd;
    Mat12 Hfd;
    for (int i = 0; i < 12; ++i) {
      Vec12 qp = q, qm = q, gp, gm;
      qp[i] += h;
      qm[i] -= h;
      gfd[i] = (segment_barrier_energy(qp, p, &gp) - segment_barrier_energy(qm, p, &gm)) / (2 * h);
      Hfd.col(i) = (gp - gm) / (2 * h);
    }
    EXPECT_LT(rel_err(g, gfd), 1e-6) << angle;
    EXPECT_LT(rel_err(H, Hfd), 1e-4) << angle;
  }
}

TEST(Barrier, ZeroBeyondActivationInfiniteAtMinimumSeparation) {
  const BarrierParams p{0.1, 0.6, 1.0};
  auto pair_at = [](double d) {
    Vec12 q;
    q << 0, 0, 0, 1, 0, 0, 0.5, -0.5, d, 0.5, 0.5, d;
    return q;
  };
  Vec12 g;
  Mat12 H;
  EXPECT_EQ(segment_barrier_energy(pair_at(0.7), p, &g, &H), 0.0);
  EXPECT_EQ(g.norm(), 0.0);
  EXPECT_EQ(H.norm(), 0.0);
  EXPECT_GT(segment_barrier_energy(pair_at(0.5), p), 0.0);
  EXPECT_TRUE(std::isinf(segment_barrier_energy(pair_at(0.1), p)));
  EXPECT_TRUE(std::isinf(segment_barrier_energy(pair_at(0.05), p)));
  // Monotone: closer is costlier.
  EXPECT_GT(segment_barrier_energy(pair_at(0.2), p), segment_barrier_energy(pair_at(0.3), p));
}
