#pragma once
// Closest distances of the two primitive pairs of surface contact (IPC, Li et al. 2020), with
// exact gradients and Hessians in their 12 vertex coordinates: a point against a triangle,
// q = [p, t0, t1, t2], and an edge against an edge, q = [a0, a1, b0, b1] (the segment distance
// of numerics/segment_distance.hpp, which the yarn's contact already uses). A point against an
// edge is the edge-edge pair with a zero-length first edge, q = [p, p, b0, b1]
// (closest_pair's degenerate case picks s = 0, so its type is a0-b0, a0-b1 or a0-b).
//
// Point-triangle types (where the closest point of the triangle lies): a vertex (3 cases, D =
// |p - t_i|^2), an edge (3 cases, the point-segment distance), or the interior,
//   D = s^2 / Q,   s = (p - t0) . N,   N = (t1 - t0) x (t2 - t0),   Q = N . N.
// In the interior's variables u = (w, e1, e2) = (p - t0, t1 - t0, t2 - t0), s is trilinear,
//   ds/dw = N, ds/de1 = e2 x w, ds/de2 = w x e1,
//   d2s/dw de1 = -[e2]x, d2s/dw de2 = [e1]x, d2s/de1 de2 = -[w]x      ([a]x b = a x b)
// and Q bilinear in (e1, e2), dQ/de1 = 2 e2 x N... (written out in the source), so
//   dD = 2 s ds / Q - s^2 dQ / Q^2,
//   d2D = (2 ds ds^T + 2 s d2s) / Q - 2 s (ds dQ^T + dQ ds^T) / Q^2 - s^2 d2Q / Q^2 + 2 s^2 dQ dQ^T / Q^3,
// mapped to q by the constant 9 x 12 matrix of u(q). Every type's formula is smooth and is
// used for the derivatives of the type the classification picked (D and its gradient are
// continuous across types; the Hessian jumps, as the segment distance's does).
#include <Eigen/Core>

#include "numerics/segment_distance.hpp"

namespace yarnhom::numerics {

enum class PointTriangleType : int {
  kT0, kT1, kT2,     // a vertex of the triangle
  kE01, kE12, kE20,  // an edge (t0-t1, t1-t2, t2-t0)
  kInterior
};
const char* to_string(PointTriangleType t);

// Where the closest point of the triangle lies, and its barycentric weights (t0, t1, t2).
struct PointTriangleClosest {
  PointTriangleType type = PointTriangleType::kInterior;
  Eigen::Vector3d bary = Eigen::Vector3d::Zero();
};
PointTriangleClosest point_triangle_closest(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                                            const Eigen::Vector3d& t1, const Eigen::Vector3d& t2);

// The squared distance of a given type (its smooth formula), with its exact derivatives.
double point_triangle_distance_squared(const Vec12& q, PointTriangleType type, Vec12* g = nullptr, Mat12* H = nullptr);
// ... of the closest type.
double point_triangle_distance_squared(const Vec12& q, Vec12* g = nullptr, Mat12* H = nullptr,
                                       PointTriangleType* type = nullptr);
double point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& t0, const Eigen::Vector3d& t1,
                               const Eigen::Vector3d& t2);

// The two kinds of contact pair, for code that handles both (barrier, CCD, friction).
enum class ContactKind : int { PointTriangle, EdgeEdge };

// Squared closest distance of a pair of the given kind, with derivatives when asked.
double contact_distance_squared(ContactKind kind, const Vec12& q, Vec12* g = nullptr, Mat12* H = nullptr);
double contact_distance(ContactKind kind, const Vec12& q);

// The closest points' weights w (4 numbers, one per vertex of q) with p_first - p_second =
// sum_k w_k q_k: point-triangle (1, -b0, -b1, -b2), edge-edge (1 - s, s, -(1 - t), -t). The
// relative motion of the closest points (friction's slip) is sum_k w_k dq_k.
Eigen::Vector4d contact_weights(ContactKind kind, const Vec12& q);

// True when segment a0-a1 crosses triangle t0-t1-t2 (closed: touching counts): the point where
// it crosses the plane tested in the triangle, in 2D; ends within 1e-12 of the sizes from the
// plane count as on it (a nearly coplanar pair is tested in the plane, where signs of rounded
// orientations would decide at random). An intersection check for tests and scene starts, not a
// solver's predicate.
bool segment_triangle_intersect(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& t0,
                                const Eigen::Vector3d& t1, const Eigen::Vector3d& t2);
// True when two triangles share a point (an edge of one crosses the other, or they touch).
// Triangles sharing a vertex are the caller's to skip.
bool triangles_intersect(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
                         const Eigen::Vector3d& b0, const Eigen::Vector3d& b1, const Eigen::Vector3d& b2);

}  // namespace yarnhom::numerics
