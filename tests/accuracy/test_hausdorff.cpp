// The Hausdorff distance between a point set and a triangle mesh (accuracy/hausdorff.hpp) and
// the point-triangle distance under it, against cases known in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "accuracy/hausdorff.hpp"
#include "accuracy/point_triangle.hpp"

using namespace yarnhom;

namespace {

// A w x l rectangle in the plane z = z0 split into 2 nx ny triangles.
void rectangle(double w, double l, int nx, int ny, double z0, Eigen::Matrix3Xd& V, Eigen::Matrix3Xi& F) {
  V.resize(3, (nx + 1) * (ny + 1));
  F.resize(3, 2 * nx * ny);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) V.col(j * (nx + 1) + i) << w * i / nx, l * j / ny, z0;
  int t = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      F.col(t++) << a, b, d;
      F.col(t++) << a, d, c;
    }
}

}  // namespace

TEST(PointTriangle, EveryVoronoiRegionAgainstDenseSampling) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-2, 2);
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::Vector3d a(U(rng), U(rng), U(rng)), b(U(rng), U(rng), U(rng)), c(U(rng), U(rng), U(rng)),
        p(U(rng), U(rng), U(rng));
    const Eigen::Vector3d q = closest_point_on_triangle(p, a, b, c);
    // q lies on the triangle: barycentric weights in [0, 1].
    Eigen::Matrix<double, 3, 2> M;
    M << b - a, c - a;
    const Eigen::Vector2d w = M.colPivHouseholderQr().solve(q - a);
    EXPECT_GE(w[0], -1e-9);
    EXPECT_GE(w[1], -1e-9);
    EXPECT_LE(w[0] + w[1], 1 + 1e-9);
    // and no sample of the triangle is closer.
    const double dq = (p - q).norm();
    const int k = 60;
    for (int i = 0; i <= k; ++i)
      for (int j = 0; i + j <= k; ++j) {
        const Eigen::Vector3d s = a + (b - a) * (double(i) / k) + (c - a) * (double(j) / k);
        EXPECT_GE((p - s).norm(), dq - 1e-12);
      }
  }
  // Degenerate (collinear) triangle: the nearest edge.
  EXPECT_NEAR(point_triangle_distance({0.5, 1, 0}, {0, 0, 0}, {1, 0, 0}, {2, 0, 0}), 1.0, 1e-14);
  // Face region: the height above the plane.
  EXPECT_NEAR(point_triangle_distance({0.2, 0.2, 0.7}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}), 0.7, 1e-14);
}

// A strip's vertices against the strip itself: 0 both ways (with a spacing above the edge length
// the surface samples are the vertices themselves).
TEST(Hausdorff, StripAgainstItselfIsZero) {
  Eigen::Matrix3Xd V;
  Eigen::Matrix3Xi F;
  rectangle(0.05, 0.10, 10, 20, 0.0, V, F);
  const HausdorffDistance h = hausdorff(V, V, F, 1.0);
  EXPECT_EQ(h.points_to_surface, 0.0);
  EXPECT_EQ(h.surface_to_points, 0.0);
  EXPECT_EQ(h.symmetric, 0.0);
}

// Points on a plane offset by d from the mesh, covering it: distance d both ways (up to the
// sampling in the surface -> points direction, bounded by the point spacing).
TEST(Hausdorff, OffsetPlaneGivesTheOffset) {
  Eigen::Matrix3Xd V, P;
  Eigen::Matrix3Xi F, FP;
  rectangle(0.05, 0.10, 5, 10, 0.0, V, F);
  rectangle(0.05, 0.10, 50, 100, 0.003, P, FP);  // dense points 1 mm apart, 3 mm above
  const HausdorffDistance h = hausdorff(P, V, F, 0.0005);
  EXPECT_NEAR(h.points_to_surface, 0.003, 1e-15);
  EXPECT_NEAR(h.mean_points_to_surface, 0.003, 1e-15);
  EXPECT_GE(h.surface_to_points, 0.003 - 1e-15);
  EXPECT_LE(h.surface_to_points, std::hypot(0.003, 0.0005 * std::sqrt(2.0)) + 1e-12);
  EXPECT_NEAR(h.symmetric, std::max(h.points_to_surface, h.surface_to_points), 0);
}

// A known asymmetric case: a unit square mesh and two points, one above its centre at height
// 0.5 and one far out in the plane at (3, 0.5, 0). points -> surface = 2 (the far point to the
// edge x = 1); surface -> points = the corner farthest from both points: the corners (0, 0) and
// (0, 1) are at distance sqrt(0.25 + 0.25 + 0.25) = sqrt(0.75) from the centre point.
TEST(Hausdorff, PointsAgainstASquareInClosedForm) {
  Eigen::Matrix3Xd V;
  Eigen::Matrix3Xi F;
  rectangle(1.0, 1.0, 4, 4, 0.0, V, F);
  Eigen::Matrix3Xd P(3, 2);
  P.col(0) << 0.5, 0.5, 0.5;
  P.col(1) << 3.0, 0.5, 0.0;
  const HausdorffDistance h = hausdorff(P, V, F, 0.01);
  EXPECT_NEAR(h.points_to_surface, 2.0, 1e-14);
  EXPECT_EQ(h.worst_point, 1);
  EXPECT_NEAR(h.surface_to_points, std::sqrt(0.75), 1e-12);  // attained at a vertex (sampled)
  EXPECT_NEAR(h.worst_surface_sample[0], 0.0, 1e-12);
  EXPECT_NEAR(h.symmetric, 2.0, 1e-14);
}

// The grid search agrees with brute force on a random cloud against a curved mesh.
TEST(Hausdorff, GridSearchMatchesBruteForce) {
  Eigen::Matrix3Xd V;
  Eigen::Matrix3Xi F;
  rectangle(0.05, 0.10, 8, 16, 0.0, V, F);
  for (Eigen::Index i = 0; i < V.cols(); ++i) V(2, i) = 0.01 * std::sin(60 * V(1, i)) * V(0, i) * 20;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(-0.02, 0.12);
  Eigen::Matrix3Xd P(3, 300);
  for (Eigen::Index i = 0; i < P.cols(); ++i) P.col(i) << U(rng) * 0.6, U(rng), 0.3 * U(rng);
  const Eigen::VectorXd d = point_mesh_distances(P, V, F);
  for (Eigen::Index i = 0; i < P.cols(); ++i) {
    double best = 1e300;
    for (Eigen::Index t = 0; t < F.cols(); ++t)
      best = std::min(best, point_triangle_distance(P.col(i), V.col(F(0, t)), V.col(F(1, t)), V.col(F(2, t))));
    EXPECT_NEAR(d[i], best, 1e-15);
  }
  const Eigen::VectorXd q = nearest_point_distances(V, P);
  for (Eigen::Index i = 0; i < V.cols(); ++i) EXPECT_NEAR(q[i], (P.colwise() - V.col(i)).colwise().norm().minCoeff(), 1e-15);
}
