// Continuous collision detection with a minimum separation: analytic cases (head-on approach:
// the exact time of reaching d_min; a pair that passes by: the whole step; a pair that would
// tunnel through between two safe end states; parallel and degenerate segments), random moves
// against dense sampling, and the swept-box broad phase against all pairs.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "numerics/ccd.hpp"

using namespace yarnhom::numerics;
using V = Eigen::Vector3d;

namespace {
Vec12 pack(const V& a0, const V& a1, const V& b0, const V& b1) {
  Vec12 q;
  q << a0, a1, b0, b1;
  return q;
}
double dist(const Vec12& q) { return segment_distance(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9)); }
}  // namespace

TEST(Ccd, HeadOnApproachStopsAtTheExactTimeOfContact) {
  // Crossed segments 1.0 apart approach along z at relative speed 1.5 over the move; d_min 0.25:
  // contact at t* = (1.0 - 0.25) / 1.5 = 0.5.
  const double dmin = 0.25;
  const Vec12 q0 = pack(V(-1, 0, 0), V(1, 0, 0), V(0, -1, 1.0), V(0, 1, 1.0));
  Vec12 q1 = q0;
  for (int k : {2, 5}) q1[k] += 0.5;     // a rises by 0.5
  for (int k : {8, 11}) q1[k] -= 1.0;    // b falls by 1.0
  const CcdResult r = segment_ccd(q0, q1, dmin);
  EXPECT_TRUE(r.hit());
  EXPECT_LE(r.t, 0.5 + 1e-15);
  EXPECT_GE(r.t, 0.5 - 1e-12);
  EXPECT_NEAR(r.d0, 1.0, 1e-15);
  EXPECT_LE(r.iterations, 3) << "a head-on approach is one advancement step";
  // Parallel segments approaching head-on: the same exact time.
  const Vec12 p0 = pack(V(0, 0, 0), V(1, 0, 0), V(0.2, 0, 1.0), V(1.2, 0, 1.0));
  Vec12 p1 = p0;
  for (int k : {8, 11}) p1[k] -= 1.5;
  const CcdResult rp = segment_ccd(p0, p1, dmin);
  EXPECT_NEAR(rp.t, 0.5, 1e-12);
  EXPECT_LE(rp.t, 0.5 + 1e-15);
}

TEST(Ccd, TunnellingBetweenTwoSafeStatesIsCaught) {
  // b passes straight through a: both end states are 1.0 apart, the middle is at distance 0.
  const double dmin = 0.2;
  const Vec12 q0 = pack(V(-1, 0, 0), V(1, 0, 0), V(0, -1, 1.0), V(0, 1, 1.0));
  Vec12 q1 = q0;
  for (int k : {8, 11}) q1[k] -= 2.0;
  EXPECT_GT(dist(q1), dmin);
  const CcdResult r = segment_ccd(q0, q1, dmin);
  EXPECT_NEAR(r.t, (1.0 - dmin) / 2.0, 1e-12);
  EXPECT_LE(r.t, (1.0 - dmin) / 2.0 + 1e-15);
}

TEST(Ccd, PairThatPassesByIsAllowedTheWholeStep) {
  // b sweeps sideways across a at height 0.3 > d_min: the closest distance is 0.3 at the
  // crossing, never d_min = 0.25.
  const double dmin = 0.25;
  const Vec12 q0 = pack(V(-1, 0, 0), V(1, 0, 0), V(-3, -1, 0.3), V(-3, 1, 0.3));
  Vec12 q1 = q0;
  for (int k : {6, 9}) q1[k] += 6.0;
  const CcdResult r = segment_ccd(q0, q1, dmin);
  EXPECT_EQ(r.t, 1.0);
  EXPECT_FALSE(r.hit());
  // The same sweep at height 0.2 < d_min does hit, where b first comes within d_min of a's end.
  Vec12 lo0 = q0, lo1 = q1;
  for (int k : {8, 11}) lo0[k] = lo1[k] = 0.2;
  const CcdResult rl = segment_ccd(lo0, lo1, dmin);
  EXPECT_TRUE(rl.hit());
  // First contact: b's x reaches -1 - sqrt(dmin^2 - 0.2^2) = -1.15: t = (3 - 1.15) / 6.
  EXPECT_NEAR(rl.t, (3.0 - 1.0 - std::sqrt(dmin * dmin - 0.04)) / 6.0, 1e-6);
  EXPECT_LE(rl.t, (3.0 - 1.0 - std::sqrt(dmin * dmin - 0.04)) / 6.0 + 1e-15);
}

TEST(Ccd, StartAtOrBelowMinimumSeparationAllowsNothing) {
  const Vec12 q0 = pack(V(-1, 0, 0), V(1, 0, 0), V(0, -1, 0.1), V(0, 1, 0.1));
  Vec12 q1 = q0;
  q1[8] += 5;
  EXPECT_EQ(segment_ccd(q0, q1, 0.2).t, 0.0);
}

TEST(Ccd, DegenerateAndStillConfigurations) {
  const double dmin = 0.1;
  // A point (zero-length segment) flying at a segment's interior: contact at (0.5-0.1)/1.
  const Vec12 q0 = pack(V(0, 0, 0), V(1, 0, 0), V(0.5, 0.5, 0), V(0.5, 0.5, 0));
  Vec12 q1 = q0;
  q1[7] -= 1.0;
  q1[10] -= 1.0;
  EXPECT_NEAR(segment_ccd(q0, q1, dmin).t, 0.4, 1e-12);
  // Two points.
  const Vec12 p0 = pack(V(0, 0, 0), V(0, 0, 0), V(1, 0, 0), V(1, 0, 0));
  Vec12 p1 = p0;
  p1[6] = p1[9] = -1;
  EXPECT_NEAR(segment_ccd(p0, p1, dmin).t, 0.45, 1e-12);
  // Nothing moves; or both translate together: always safe.
  EXPECT_EQ(segment_ccd(q0, q0, dmin).t, 1.0);
  Vec12 q2 = q0;
  for (int k = 0; k < 12; k += 3) q2[k] += 7.0;
  EXPECT_EQ(segment_ccd(q0, q2, dmin).t, 1.0);
}

TEST(Ccd, NeverOverstatesTheSafeFractionOnRandomMoves) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> U(-1, 1);
  const double dmin = 0.15;
  int hits = 0, misses = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Vec12 q0 = Vec12::NullaryExpr([&](Eigen::Index) { return U(rng); });
    const Vec12 q1 = q0 + Vec12::NullaryExpr([&](Eigen::Index) { return 1.5 * U(rng); });
    if (dist(q0) <= dmin) continue;
    const CcdResult r = segment_ccd(q0, q1, dmin);
    // Sampled densely: the distance stays above d_min on [0, t] ...
    double first = 2.0;  // first sampled time at or below d_min
    for (int k = 0; k <= 4000; ++k) {
      const double t = k / 4000.0;
      const double d = dist(q0 + t * (q1 - q0));
      if (t <= r.t) {
        EXPECT_GT(d, dmin * (1 - 1e-9)) << trial << " t " << t;
      }
      if (d <= dmin && first > 1) first = t;
    }
    if (r.hit()) {
      ++hits;
      // ... and a reported contact is real: d_min is reached right after t.
      EXPECT_LT(dist(q0 + r.t * (q1 - q0)) - dmin, 1e-5 * (r.d0 - dmin)) << trial;
      EXPECT_LE(r.t, first);
    } else {
      ++misses;
      EXPECT_GT(first, 1.0) << trial;
    }
  }
  EXPECT_GT(hits, 30);
  EXPECT_GT(misses, 30);
}

TEST(Ccd, SweptBroadPhaseFindsEveryPairThatComesWithinReach) {
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> U(0, 1);
  auto random_moves = [&](int n) {
    std::vector<SegmentMove> m(n);
    for (auto& s : m) {
      const V c(5 * U(rng), 5 * U(rng), 5 * U(rng)), e(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5), d(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5);
      s.start = {c - 0.5 * e, c + 0.5 * e};
      s.end = {c - 0.5 * e + d, c + 0.5 * e + 1.3 * d};
    }
    return m;
  };
  const auto a = random_moves(150), b = random_moves(200);
  const double reach = 0.2;
  const auto pairs = swept_pairs(a, b, reach);
  std::set<std::pair<int, int>> found(pairs.begin(), pairs.end());
  EXPECT_EQ(found.size(), pairs.size()) << "no duplicates";
  int close = 0;
  for (int i = 0; i < 150; ++i)
    for (int j = 0; j < 200; ++j) {
      const auto [q0, q1] = pair_move(a[i], b[j]);
      double dmin = 1e300;
      for (int k = 0; k <= 50; ++k) dmin = std::min(dmin, dist(q0 + (k / 50.0) * (q1 - q0)));
      if (dmin < reach) {
        ++close;
        EXPECT_TRUE(found.count({i, j})) << i << " " << j;
      }
    }
  EXPECT_GT(close, 50);
  EXPECT_LT(pairs.size(), 150u * 200u / 4) << "a broad phase, not all pairs";
}
