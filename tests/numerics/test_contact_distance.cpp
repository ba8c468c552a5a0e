// Point-triangle and edge-edge contact: the point-triangle distance against a brute-force
// minimum and every type's exact gradient and Hessian against central differences; the
// contact barrier's derivatives; CCD's safe fraction (never closer than its target on [0, t],
// exact on a head-on approach); the broad phase against all pairs (and their order); the exact triangle-triangle
// intersection test on hand-made and random cases.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <random>

#include "numerics/contact_pairs.hpp"

using namespace yarnhom::numerics;
using V = Eigen::Vector3d;

namespace {

Vec12 pack(const V& a, const V& b, const V& c, const V& d) {
  Vec12 q;
  q << a, b, c, d;
  return q;
}

// min over a fine barycentric grid and the three edges (exact per edge).
double brute_point_triangle(const V& p, const V& a, const V& b, const V& c) {
  auto seg = [&](const V& u, const V& w) {
    const V e = w - u;
    const double t = std::clamp((p - u).dot(e) / e.squaredNorm(), 0.0, 1.0);
    return (p - u - t * e).norm();
  };
  double d = std::min({seg(a, b), seg(b, c), seg(c, a)});
  const int n = 400;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) d = std::min(d, (p - (a + (b - a) * i / n + (c - a) * j / n)).norm());
  return d;
}

template <class F>
void check_fd(const Vec12& q, F&& f, double tol, const std::string& what) {
  Vec12 g;
  Mat12 H;
  f(q, &g, &H);
  const double h = 1e-6;
  Vec12 gfd;
  Mat12 Hfd;
  for (int i = 0; i < 12; ++i) {
    Vec12 qp = q, qm = q, gp, gm;
    qp[i] += h;
    qm[i] -= h;
    gfd[i] = (f(qp, &gp, nullptr) - f(qm, &gm, nullptr)) / (2 * h);
    Hfd.col(i) = (gp - gm) / (2 * h);
  }
  EXPECT_LT((g - gfd).norm(), tol * std::max(1.0, gfd.norm())) << what;
  EXPECT_LT((H - Hfd).norm(), tol * std::max(1.0, Hfd.norm())) << what;
  EXPECT_LT((H - H.transpose()).norm(), 1e-10 * (1 + H.norm())) << what;
}

}  // namespace

TEST(ContactDistance, PointTriangleMatchesBruteForceAndFindsEveryType) {
  const V a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  struct Case {
    V p;
    PointTriangleType type;
  } cases[] = {{V(-0.5, -0.5, 0.3), PointTriangleType::kT0}, {V(1.5, -0.2, -0.1), PointTriangleType::kT1},
               {V(-0.1, 1.6, 0.2), PointTriangleType::kT2}, {V(0.5, -0.4, 0.2), PointTriangleType::kE01},
               {V(0.8, 0.8, -0.3), PointTriangleType::kE12}, {V(-0.3, 0.5, 0.1), PointTriangleType::kE20},
               {V(0.2, 0.3, 0.4), PointTriangleType::kInterior}};
  for (const Case& k : cases) {
    PointTriangleType t;
    const double D = point_triangle_distance_squared(pack(k.p, a, b, c), nullptr, nullptr, &t);
    EXPECT_EQ(t, k.type) << to_string(k.type);
    EXPECT_NEAR(std::sqrt(D), brute_point_triangle(k.p, a, b, c), 1e-12) << to_string(k.type);
  }
  std::mt19937 rng(7);
  std::normal_distribution<double> N(0, 1);
  for (int i = 0; i < 200; ++i) {
    const V p(N(rng), N(rng), N(rng)), t0(N(rng), N(rng), N(rng)), t1(N(rng), N(rng), N(rng)), t2(N(rng), N(rng), N(rng));
    const double d = point_triangle_distance(p, t0, t1, t2), ref = brute_point_triangle(p, t0, t1, t2);
    EXPECT_LE(d, ref + 1e-12);          // never above a point of the triangle
    EXPECT_GT(d, ref - 1e-2 * (1 + ref));  // the grid's resolution
  }
}

TEST(ContactDistance, PointTriangleDerivativesMatchFiniteDifferencesForEveryType) {
  std::mt19937 rng(3);
  std::normal_distribution<double> N(0, 1);
  int seen[7] = {0};
  for (int i = 0; i < 400; ++i) {
    const Vec12 q = pack(V(N(rng), N(rng), N(rng)) * 2, V(N(rng), N(rng), N(rng)), V(N(rng), N(rng), N(rng)),
                         V(N(rng), N(rng), N(rng)));
    PointTriangleType t;
    point_triangle_distance_squared(q, nullptr, nullptr, &t);
    if (seen[int(t)]++ >= 5) continue;
    check_fd(q, [&](const Vec12& x, Vec12* g, Mat12* H) { return point_triangle_distance_squared(x, t, g, H); }, 1e-6,
             to_string(t));
  }
  for (int k = 0; k < 7; ++k) EXPECT_GT(seen[k], 0) << to_string(PointTriangleType(k));
}

TEST(ContactDistance, BarrierDerivativesMatchFiniteDifferencesForBothKinds) {
  const BarrierParams p{0.0, 0.5, 3.0}, thick{0.1, 0.6, 2.0};
  const Vec12 pt = pack(V(0.2, 0.3, 0.25), V(0, 0, 0), V(1, 0, 0.1), V(0, 1, -0.05));
  const Vec12 ee = pack(V(0.1, 0.5, 0.3), V(0.9, 0.4, 0.2), V(0.5, 0, 0), V(0.4, 1, 0.1));
  for (const BarrierParams& bp : {p, thick}) {
    check_fd(pt, [&](const Vec12& x, Vec12* g, Mat12* H) { return contact_barrier_energy(ContactKind::PointTriangle, x, bp, g, H); },
             1e-5, "point-triangle");
    check_fd(ee, [&](const Vec12& x, Vec12* g, Mat12* H) { return contact_barrier_energy(ContactKind::EdgeEdge, x, bp, g, H); },
             1e-5, "edge-edge");
  }
  EXPECT_EQ(contact_barrier_energy(ContactKind::PointTriangle, pack(V(0.2, 0.2, 0.6), V(0, 0, 0), V(1, 0, 0), V(0, 1, 0)), p), 0.0);
  EXPECT_TRUE(std::isinf(contact_barrier_energy(ContactKind::PointTriangle, pack(V(0, 0, 0), V(0, 0, 0), V(1, 0, 0), V(0, 1, 0)), p)));
  EXPECT_TRUE(std::isinf(contact_barrier_energy(ContactKind::EdgeEdge, pack(V(0.05, 0, 0), V(1, 0, 0), V(0, 0, 0), V(0, 1, 0)), thick)));
}

TEST(ContactDistance, CcdNeverClosesMoreThanItsShareOfTheGap) {
  std::mt19937 rng(11);
  std::normal_distribution<double> N(0, 1);
  int hits = 0;
  for (int i = 0; i < 300; ++i) {
    const ContactKind kind = i % 2 ? ContactKind::EdgeEdge : ContactKind::PointTriangle;
    Vec12 q0, dq;
    for (int k = 0; k < 12; ++k) q0[k] = N(rng), dq[k] = 2 * N(rng);
    const double dmin = i % 3 == 0 ? 0.05 : 0.0, eta = 0.1;
    const CcdResult r = contact_ccd(kind, q0, q0 + dq, dmin, eta);
    if (r.d0 <= dmin) continue;
    hits += r.hit();
    const double target = dmin + eta * (r.d0 - dmin);
    for (int s = 0; s <= 200; ++s) EXPECT_GE(contact_distance(kind, q0 + (r.t * s / 200) * dq), target * (1 - 1e-9));
  }
  EXPECT_GT(hits, 20);
  // Head-on: a point falling onto a triangle's interior from 1.0 by 2.0 hits at t = 0.5; the
  // fraction keeping 10 % of the gap is 0.45.
  const Vec12 q0 = pack(V(0.2, 0.2, 1), V(0, 0, 0), V(1, 0, 0), V(0, 1, 0)), q1 = pack(V(0.2, 0.2, -1), V(0, 0, 0), V(1, 0, 0), V(0, 1, 0));
  EXPECT_NEAR(contact_ccd(ContactKind::PointTriangle, q0, q1, 0.0, 0.1).t, 0.45, 1e-12);
}

TEST(ContactDistance, BoxPairsFindExactlyTheOverlappingPairsInOrder) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0, 1);
  // 9,000 boxes (enough for the grid's and the queries' parallel passes), a few long ones, a cluster far away
  // (the grid coarsens), boxes touching exactly, and boxes with infinite or NaN coordinates.
  std::vector<Box3> a, b;
  for (int i = 0; i < 9000; ++i) {
    const V c = V(U(rng), U(rng), 0.1 * U(rng)) + (i % 97 == 0 ? V(40, -30, 20) : V::Zero());
    a.push_back(points_box(0.002 + 0.01 * U(rng), c));
    b.push_back(points_box(0.0, c, V(c + V(U(rng), U(rng), U(rng)) * (i % 500 == 0 ? 0.5 : 0.01))));
  }
  b[7] = {a[3].hi, a[3].hi + V(1e-3, 1e-3, 1e-3)};  // touches a[3] at a corner: a pair (closed)
  const double inf = std::numeric_limits<double>::infinity();
  a[11].lo[0] = a[11].lo[2] = -inf;  // a slab across x and z
  a[11].hi[0] = a[11].hi[2] = inf;
  a[12].lo[1] = std::numeric_limits<double>::quiet_NaN();
  b[13].lo[2] = -inf;
  b[14].hi[0] = std::numeric_limits<double>::quiet_NaN();
  const int saved = omp_get_max_threads();
  for (bool same : {false, true}) {
    const std::vector<Box3>& bb = same ? a : b;
    omp_set_num_threads(3);  // the grid and the queries on 3 threads, then on one: the same list
    const auto got = box_pairs(a, bb, same);
    omp_set_num_threads(1);
    EXPECT_EQ(box_pairs(a, bb, same), got);
    omp_set_num_threads(saved);
    std::vector<std::pair<int, int>> ref;  // by j, then i
    for (int j = 0; j < int(bb.size()); ++j)
      for (int i = 0; i < (same ? j : int(a.size())); ++i)
        if (a[i].overlaps(bb[j])) ref.emplace_back(i, j);
    EXPECT_GT(ref.size(), 2000u);
    EXPECT_EQ(got, ref) << same;
    if (!same) {
      EXPECT_TRUE(std::find(got.begin(), got.end(), std::make_pair(3, 7)) != got.end());
    }
    int with_infinite = 0;
    for (const auto& [i, j] : got) with_infinite += i == 11 || (!same && j == 13);
    EXPECT_GT(with_infinite, 10);
  }
}

TEST(ContactDistance, BoxPairsOfFlatSheetsWhoseGridCapCoarsensTheThinAxis) {
  // Two parallel sheets of zero-thickness boxes (a cloth's first frame: flat panels, boxes of no
  // extent across them) and a third sheet across them: the grid's thin cells are the ones the
  // cell cap merges (numerics/box_pairs.cpp); the pairs are exactly the brute force's.
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Box3> a;
  for (int i = 0; i < 9000; ++i) {
    const int sheet = i % 3;
    const V c = sheet < 2 ? V(U(rng), 0.3 * sheet, U(rng)) : V(U(rng), 0.3 * U(rng), 0.5);
    const V e = sheet < 2 ? V(0.01 * U(rng), 0.0, 0.01 * U(rng)) : V(0.01 * U(rng), 0.01 * U(rng), 0.0);
    a.push_back({c, c + e});
  }
  const auto got = box_pairs(a, a, true);
  std::vector<std::pair<int, int>> ref;
  for (int j = 0; j < int(a.size()); ++j)
    for (int i = 0; i < j; ++i)
      if (a[i].overlaps(a[j])) ref.emplace_back(i, j);
  EXPECT_GT(ref.size(), 1000u);
  EXPECT_EQ(got, ref);
}

TEST(ContactDistance, TriangleIntersectionOnHandMadeAndRandomCases) {
  const V a0(0, 0, 0), a1(1, 0, 0), a2(0, 1, 0);
  // Pierced through the interior, no vertex near: intersects.
  EXPECT_TRUE(triangles_intersect(a0, a1, a2, V(0.2, 0.2, -1), V(0.3, 0.2, 1), V(5, 5, 0.5)));
  // Parallel above: no.
  EXPECT_FALSE(triangles_intersect(a0, a1, a2, V(0, 0, 1e-9), V(1, 0, 1e-9), V(0, 1, 1e-9)));
  // Coplanar, one inside the other (no edges cross): yes.
  EXPECT_TRUE(triangles_intersect(a0, a1, a2, V(0.1, 0.1, 0), V(0.2, 0.1, 0), V(0.1, 0.2, 0)));
  // Coplanar, apart: no.
  EXPECT_FALSE(triangles_intersect(a0, a1, a2, V(1, 1, 0), V(2, 1, 0), V(1, 2, 0)));
  // Touching at a point: yes (closed).
  EXPECT_TRUE(triangles_intersect(a0, a1, a2, V(0.5, 0.5, 0), V(1, 1, 1), V(1, 1, -1)));
  // Far apart in one tilted plane (a flat sheet's non-adjacent triangles): no, whatever the
  // rounding of the tilt.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, V(1, 2, 3).normalized()).toRotationMatrix();
  for (int k = 0; k < 50; ++k) {
    const V o(0.0137 * k, 0.011 * k, 0);
    EXPECT_FALSE(triangles_intersect(R * a0, R * a1, R * a2, R * (o + V(2, 0, 0)), R * (o + V(3, 0, 0)), R * (o + V(2, 1, 0))));
    EXPECT_TRUE(triangles_intersect(R * a0, R * a1, R * a2, R * (o * 0 + V(0.2, 0.2, 0)), R * V(0.3, 0.2, 0), R * V(0.2, 0.3, 0)));
  }
  // Random: intersecting pairs have distance 0 between some edge and the other triangle, and
  // separated ones are found apart by a positive margin of the point-triangle/edge distances.
  std::mt19937 rng(9);
  std::normal_distribution<double> N(0, 1);
  int yes = 0, no = 0;
  for (int i = 0; i < 2000; ++i) {
    V t[6];
    for (V& v : t) v = V(N(rng), N(rng), N(rng));
    const bool x = triangles_intersect(t[0], t[1], t[2], t[3], t[4], t[5]);
    double d = INFINITY;
    for (int k = 0; k < 3; ++k) {
      d = std::min(d, point_triangle_distance(t[k], t[3], t[4], t[5]));
      d = std::min(d, point_triangle_distance(t[3 + k], t[0], t[1], t[2]));
      for (int l = 0; l < 3; ++l) d = std::min(d, segment_distance(t[k], t[(k + 1) % 3], t[3 + l], t[3 + (l + 1) % 3]));
    }
    // Disjoint triangles are at the distance d > 0 of their closest features; intersecting
    // ones that only cross in their interiors can still have d > 0, so only "d == 0 => x" and
    // "!x => d > 0" are checked, plus a sampled interior crossing test below.
    if (!x) EXPECT_GT(d, 0.0);
    yes += x, no += !x;
    // An intersection means some edge of one passes through the other: its segment then
    // has a point on the other triangle's plane inside the triangle.
    if (x) {
      bool found = false;
      for (int k = 0; k < 6 && !found; ++k) {
        const V& p = t[k], &q = t[k < 3 ? (k + 1) % 3 : 3 + (k + 1) % 3];
        const V* T = k < 3 ? t + 3 : t;
        for (int s = 0; s <= 2000 && !found; ++s)
          found = point_triangle_distance(p + (q - p) * (s / 2000.0), T[0], T[1], T[2]) < 2e-3 * (q - p).norm();
      }
      EXPECT_TRUE(found);
    }
  }
  EXPECT_GT(yes, 100);
  EXPECT_GT(no, 100);
}
