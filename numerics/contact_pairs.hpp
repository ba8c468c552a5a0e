#pragma once
// What a surface contact pair needs beyond its distance (numerics/contact_distance.hpp): IPC's
// log barrier on the squared distance, continuous collision detection of a straight move, and
// the broad phase that finds the pairs to test.
//
// Barrier: the yarn's (numerics/barrier.hpp) on a pair of either kind, E = kappa b(z),
//   z = (D - d_min^2) / (d_hat^2 - d_min^2),
// D the squared closest distance; d_min > 0 gives a thickness (a capsule's radius around its
// axis), d_min = 0 the plain IPC barrier of cloth against cloth.
//
// CCD (additive CCD's conservative advancement, Li et al. 2021, as segment_ccd of
// numerics/ccd.hpp): along a straight move of the four vertices, the closest distance changes
// no faster than l = |dq0 - m| + max_k |dq_k - m| (point-triangle: every point of the
// triangle moves by a convex combination of its vertices' displacements) or the edge-edge
// bound of segment_ccd. The returned fraction t is safe: on [0, t] the distance stays above
// d_min + eta (d(0) - d_min), eta in (0, 1): the move never closes more than 1 - eta of the
// gap (ACCD's "s"), so what follows starts with a positive distance.
//
// Broad phase: boxes of points, edges and triangles (each over a whole move, inflated by a
// reach), the pairs whose boxes overlap (numerics/box_pairs.hpp). The caller drops pairs sharing
// a vertex.
#include <Eigen/Core>
#include <functional>
#include <utility>
#include <vector>

#include "numerics/barrier.hpp"
#include "numerics/box_pairs.hpp"
#include "numerics/ccd.hpp"
#include "numerics/contact_distance.hpp"
#include "numerics/hash_grid.hpp"

namespace yarnhom::numerics {

// kappa b(z(D(q))) with its exact gradient and Hessian in q (not projected); 0 beyond d_hat,
// +inf at or below d_min.
double contact_barrier_energy(ContactKind kind, const Vec12& q, const BarrierParams& p, Vec12* g = nullptr,
                              Mat12* H = nullptr);

// The bound l above for a pair whose four points move by dq (q1 - q0): on any straight move of
// the pair by dq, the closest distance changes by at most l (from wherever it starts).
double contact_speed(ContactKind kind, const Vec12& dq);

// Safe fraction of the move q0 -> q1 (see above). t = 0 when d(0) <= d_min.
CcdResult contact_ccd(ContactKind kind, const Vec12& q0, const Vec12& q1, double dmin, double eta = 0.1,
                      const CcdOptions& opt = {});

// Box of a set of points (one position each, or a start and an end per point), inflated by reach.
template <class... P>
Box3 points_box(double reach, const Eigen::Vector3d& first, const P&... rest) {
  Box3 b{first, first};
  ((b.lo = b.lo.cwiseMin(rest), b.hi = b.hi.cwiseMax(rest)), ...);
  b.lo.array() -= reach;
  b.hi.array() += reach;
  return b;
}

}  // namespace yarnhom::numerics
