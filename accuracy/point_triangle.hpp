#pragma once
// The point of a triangle nearest to a given point, for the Hausdorff distance between yarn
// centrelines and a continuum surface (accuracy/hausdorff.hpp).
#include <Eigen/Dense>

namespace yarnhom {

// Closest point of triangle (a, b, c) to p, by the Voronoi region of the triangle that p falls
// in (three vertex regions, three edge regions, the face): each region is decided by the signs
// of a few dot products, so the result is exact up to rounding, also for degenerate (needle or
// zero-area) triangles, where it falls back to the nearest edge.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

inline double point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c) {
  return (p - closest_point_on_triangle(p, a, b, c)).norm();
}

}  // namespace yarnhom
