#pragma once
// Hausdorff distance between a point set (the yarn centreline vertices of a yarn-level strip)
// and a triangle mesh (the continuum strip's surface), supplement section 4.2 / Table 5.
//
// What is measured, exactly:
//   points -> surface: max over the points p of min over the triangles T of |p - T|, the
//                      exact point-to-triangle distance (accuracy/point_triangle.hpp);
//   surface -> points: max over the surface points q of min over the points p of |q - p|,
//                      with the surface sampled at its vertices and at a regular barycentric
//                      subdivision of every triangle, fine enough that every surface point is
//                      within `spacing` of a sample (so this direction is exact to within
//                      `spacing`, from below);
//   symmetric:         the larger of the two.
// Both sets are used as given: same frame, same units (the caller aligns them).
#include <Eigen/Dense>

namespace yarnhom {

struct HausdorffDistance {
  double points_to_surface = 0;  // directed, exact
  double surface_to_points = 0;  // directed, over the samples
  double symmetric = 0;          // max of the two
  double mean_points_to_surface = 0;
  Eigen::Index worst_point = -1;           // the point farthest from the surface
  Eigen::Vector3d worst_surface_sample{0, 0, 0};  // the surface sample farthest from the points
};

// Distance of every point (columns of P) to the mesh (V: 3 x nv, F: 3 x nf vertex indices).
Eigen::VectorXd point_mesh_distances(const Eigen::Matrix3Xd& P, const Eigen::Matrix3Xd& V, const Eigen::Matrix3Xi& F);

// Distance of every query point (columns of Q) to the nearest of the points P.
Eigen::VectorXd nearest_point_distances(const Eigen::Matrix3Xd& Q, const Eigen::Matrix3Xd& P);

// The mesh's vertices and, per triangle, the interior and edge points of its subdivision into
// k^2 similar triangles, k the smallest with (longest edge)/k <= spacing. Every point of the
// surface is within `spacing` of a sample.
Eigen::Matrix3Xd sample_surface(const Eigen::Matrix3Xd& V, const Eigen::Matrix3Xi& F, double spacing);

HausdorffDistance hausdorff(const Eigen::Matrix3Xd& P, const Eigen::Matrix3Xd& V, const Eigen::Matrix3Xi& F,
                            double spacing);

}  // namespace yarnhom
