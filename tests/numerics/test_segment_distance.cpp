// Closest distance between two segments: the type and the distance against an independent
// enumeration of every candidate (4 point-point, 4 point-edge, the edge-edge optimum), the
// exact gradient and Hessian against central finite differences for every type, nearly
// parallel, parallel and degenerate segments, rigid invariance.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "numerics/segment_distance.hpp"

using namespace yarnhom::numerics;

namespace {
// |a - b| / |b| (Frobenius), b floored.
double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor = 1e-300) {
  return (a - b).norm() / std::max(b.norm(), floor);
}
}  // namespace

namespace {

using V = Eigen::Vector3d;

Vec12 pack(const V& a0, const V& a1, const V& b0, const V& b1) {
  Vec12 q;
  q << a0, a1, b0, b1;
  return q;
}

double point_segment(const V& p, const V& e0, const V& e1) {
  const V e = e1 - e0;
  const double t = std::clamp((p - e0).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (p - e0 - t * e).norm();
}

// The closest distance as the minimum over every candidate, computed independently of
// closest_pair: the minimum of a convex quadratic over the unit square lies at the
// unconstrained optimum (if inside) or on an edge of the square (a point-segment distance).
double reference_distance(const Vec12& q) {
  const V a0 = q.segment<3>(0), a1 = q.segment<3>(3), b0 = q.segment<3>(6), b1 = q.segment<3>(9);
  double d = std::min({point_segment(a0, b0, b1), point_segment(a1, b0, b1), point_segment(b0, a0, a1),
                       point_segment(b1, a0, a1)});
  const V ea = a1 - a0, eb = b1 - b0, w = a0 - b0;
  const double A = ea.squaredNorm(), B = ea.dot(eb), E = eb.squaredNorm(), det = A * E - B * B;
  if (det > 1e-14 * A * E) {
    const double s = (B * eb.dot(w) - ea.dot(w) * E) / det, t = (A * eb.dot(w) - B * ea.dot(w)) / det;
    if (s > 0 && s < 1 && t > 0 && t < 1) d = std::min(d, (a0 + s * ea - b0 - t * eb).norm());
  }
  return d;
}

// Central differences of the type's formula (the type is held: the derivatives of one smooth piece).
void check_derivatives(const Vec12& q, SegmentDistanceType type, double grad_tol, double hess_tol,
                       const std::string& what, double rel_step = 1e-6) {
  Vec12 g;
  Mat12 H;
  segment_distance_squared(q, type, &g, &H);
  const double h = rel_step * q.cwiseAbs().maxCoeff();
  Vec12 gfd;
  Mat12 Hfd;
  for (int i = 0; i < 12; ++i) {
    Vec12 qp = q, qm = q, gp, gm;
    qp[i] += h;
    qm[i] -= h;
    gfd[i] = (segment_distance_squared(qp, type, &gp) - segment_distance_squared(qm, type, &gm)) / (2 * h);
    Hfd.col(i) = (gp - gm) / (2 * h);
  }
  EXPECT_LT(rel_err(g, gfd), grad_tol) << what;
  EXPECT_LT(rel_err(H, Hfd), hess_tol) << what;
  EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm() + 1e-300) << what;
}

}  // namespace

TEST(SegmentDistance, EveryTypeIsFoundAndHasTheRightDistance) {
  // One hand-made configuration per type: a along x from 0 to 1, b placed so that the closest
  // pair is the named one.
  const V a0(0, 0, 0), a1(1, 0, 0);
  struct Case {
    V b0, b1;
    SegmentDistanceType type;
    double d;
  };
  const Case cases[] = {
      {V(-1, 0, 1), V(-2, 0, 1), SegmentDistanceType::kA0B0, std::sqrt(2.0)},
      {V(-2, 0, 1), V(-1, 0, 1), SegmentDistanceType::kA0B1, std::sqrt(2.0)},
      {V(2, 0, 1), V(3, 0, 1), SegmentDistanceType::kA1B0, std::sqrt(2.0)},
      {V(3, 0, 1), V(2, 0, 1), SegmentDistanceType::kA1B1, std::sqrt(2.0)},
      {V(-1, -1, 0.5), V(-1, 1, 0.5), SegmentDistanceType::kA0B, std::sqrt(1.25)},
      {V(2, -1, 0.5), V(2, 1, 0.5), SegmentDistanceType::kA1B, std::sqrt(1.25)},
      {V(0.3, 0.2, 0.7), V(0.3, 2, 3), SegmentDistanceType::kAB0, std::sqrt(0.53)},
      {V(0.6, 2, 3), V(0.6, 0.2, 0.7), SegmentDistanceType::kAB1, std::sqrt(0.53)},
      {V(0.4, -1, 0.3), V(0.4, 1, 0.3), SegmentDistanceType::kAB, 0.3},
  };
  for (const Case& c : cases) {
    const ClosestPair cp = closest_pair(a0, a1, c.b0, c.b1);
    EXPECT_EQ(cp.type, c.type) << to_string(c.type) << " found " << to_string(cp.type);
    EXPECT_NEAR(segment_distance(a0, a1, c.b0, c.b1), c.d, 1e-14) << to_string(c.type);
    SegmentDistanceType t;
    EXPECT_NEAR(segment_distance_squared(pack(a0, a1, c.b0, c.b1), nullptr, nullptr, &t), c.d * c.d, 1e-14);
    EXPECT_EQ(t, c.type);
  }
}

TEST(SegmentDistance, MatchesTheEnumerationOfAllCandidates) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  int counts[9] = {0};
  for (int trial = 0; trial < 4000; ++trial) {
    const Vec12 q = Vec12::NullaryExpr([&](Eigen::Index) { return U(rng); });
    SegmentDistanceType type;
    const double D = segment_distance_squared(q, nullptr, nullptr, &type);
    ++counts[static_cast<int>(type)];
    EXPECT_NEAR(std::sqrt(D), reference_distance(q), 1e-12) << trial;
  }
  for (int k = 0; k < 9; ++k) EXPECT_GT(counts[k], 20) << "type " << to_string(SegmentDistanceType(k)) << " rarely seen";
}

TEST(SegmentDistance, GradientAndHessianMatchFiniteDifferencesForEveryType) {
  // Random configurations, each checked with the type closest_pair finds (well inside its
  // region: the minimizer is not near a boundary of the unit square, so the type is held by
  // the finite differences too).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  int checked[9] = {0};
  for (int trial = 0; trial < 3000; ++trial) {
    const Vec12 q = Vec12::NullaryExpr([&](Eigen::Index) { return U(rng); });
    const ClosestPair cp = closest_pair(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
    auto inside = [](double x) { return x == 0 || x == 1 || (x > 0.05 && x < 0.95); };
    if (!inside(cp.s) || !inside(cp.t)) continue;
    const int k = static_cast<int>(cp.type);
    if (checked[k] >= 8) continue;
    ++checked[k];
    // Every type's formula is smooth; its gradient through a clamped end is Danskin's.
    check_derivatives(q, cp.type, 1e-7, 1e-6, std::string("type ") + to_string(cp.type));
  }
  for (int k = 0; k < 9; ++k) EXPECT_EQ(checked[k], 8) << to_string(SegmentDistanceType(k));
}

TEST(SegmentDistance, NearlyParallelSegments) {
  // Two segments 0.3 apart crossing at a small angle: edge-edge down to angles of 1e-3 rad,
  // with exact derivatives (large second derivatives: the closest points move fast).
  for (double angle : {0.1, 1e-2, 1e-3}) {
    const V a0(0, 0, 0), a1(1, 0, 0);
    const V dir(std::cos(angle), std::sin(angle), 0);
    const V b0 = V(0.5, 0, 0.3) - 0.4 * dir, b1 = V(0.5, 0, 0.3) + 0.4 * dir;
    const Vec12 q = pack(a0, a1, b0, b1);
    SegmentDistanceType t;
    EXPECT_NEAR(std::sqrt(segment_distance_squared(q, nullptr, nullptr, &t)), 0.3, 1e-13);
    EXPECT_EQ(t, SegmentDistanceType::kAB) << angle;
    // The closest points move by ~1/angle per unit of endpoint motion: steps shrink with the angle.
    check_derivatives(q, t, 1e-7, 1e-5, "angle " + std::to_string(angle), 1e-5 * angle);
  }
  // Across the parallel threshold (1e-6 rad) the distance is continuous: the end-point pair
  // used for parallel segments is within round-off of the edge-edge distance.
  const V a0(0, 0, 0), a1(1, 0, 0);
  double below = 0, above = 0;
  for (double angle : {0.5e-6, 2e-6}) {
    const V dir(std::cos(angle), std::sin(angle), 0);
    const double d = segment_distance(a0, a1, V(0.5, 0, 0.3) - 0.4 * dir, V(0.5, 0, 0.3) + 0.4 * dir);
    (angle < 1e-6 ? below : above) = d;
  }
  EXPECT_NEAR(below, 0.3, 1e-12);
  EXPECT_NEAR(above, 0.3, 1e-12);
}

TEST(SegmentDistance, ParallelAndDegenerateSegments) {
  const V a0(0, 0, 0), a1(1, 0, 0);
  // Exactly parallel, overlapping: the distance is the offset, with one end in the overlap.
  {
    const V b0(0.5, 0.2, 0.1), b1(1.7, 0.2, 0.1);
    const ClosestPair cp = closest_pair(a0, a1, b0, b1);
    EXPECT_NEAR(segment_distance(a0, a1, b0, b1), std::sqrt(0.05), 1e-15);
    EXPECT_NE(cp.type, SegmentDistanceType::kAB);
    // The gradient (Danskin) is the pull along the offset: finite differences agree along
    // the normal direction, where the function is smooth.
    Vec12 g;
    const Vec12 q = pack(a0, a1, b0, b1);
    segment_distance_squared(q, &g);
    const double h = 1e-7;
    Vec12 dir = Vec12::Zero();
    dir.segment<3>(6) = dir.segment<3>(9) = V(0, 0.2, 0.1).normalized();
    const double fd = (segment_distance_squared(q + h * dir) - segment_distance_squared(q - h * dir)) / (2 * h);
    EXPECT_NEAR(g.dot(dir), fd, 1e-8);
  }
  // Parallel, collinear and disjoint: end to end.
  EXPECT_NEAR(segment_distance(a0, a1, V(1.5, 0, 0), V(3, 0, 0)), 0.5, 1e-15);
  // Zero-length segments: point to segment, point to point.
  EXPECT_NEAR(segment_distance(a0, a1, V(0.3, 0.4, 0), V(0.3, 0.4, 0)), 0.4, 1e-15);
  EXPECT_NEAR(segment_distance(V(0.3, 0.4, 0), V(0.3, 0.4, 0), a0, a1), 0.4, 1e-15);
  EXPECT_NEAR(segment_distance(V(1, 1, 1), V(1, 1, 1), V(1, 1, 2), V(1, 1, 2)), 1.0, 1e-15);
  // Intersecting segments: distance 0, edge-edge.
  EXPECT_EQ(closest_pair(a0, a1, V(0.5, -1, 0), V(0.5, 1, 0)).type, SegmentDistanceType::kAB);
  EXPECT_NEAR(segment_distance(a0, a1, V(0.5, -1, 0), V(0.5, 1, 0)), 0.0, 1e-15);
}

TEST(SegmentDistance, InvariantUnderRigidMotion) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 100; ++trial) {
    const Vec12 q = Vec12::NullaryExpr([&](Eigen::Index) { return U(rng); });
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3 + trial, V(1, 2, -1).normalized()).toRotationMatrix();
    Vec12 qr;
    for (int k = 0; k < 4; ++k) qr.segment<3>(3 * k) = R * q.segment<3>(3 * k) + V(0.5, -2, 3);
    EXPECT_NEAR(segment_distance_squared(qr), segment_distance_squared(q), 1e-13);
  }
}
