#pragma once
// Continuous collision detection with a minimum separation, for segments whose endpoints move
// along straight lines (as the RVE's vertices do along a Newton step at fixed strain: x is
// linear in the fluctuations). Conservative advancement (the scheme of additive CCD, Li et
// al. 2021): along the move the closest distance d(t) of a pair changes at most as fast as
// the largest relative endpoint speed,
//
//   |d'(t)| <= l = max(|da0 - m|, |da1 - m|) + max(|db0 - m|, |db1 - m|),
//
// (dk the endpoint displacements over the whole move, m their mean: a common translation does
// not change distances; every point of a segment moves by a convex combination of its
// endpoints' displacements). So from a time t with distance d(t) > d_min the move is safe up
// to t + (d(t) - d_min) / l, where d is evaluated again. The result never overstates the safe
// fraction (up to the round-off of one distance evaluation); it is exact for a head-on
// approach, and converges to the first time of contact geometrically otherwise.
#include <Eigen/Core>
#include <array>
#include <utility>
#include <vector>

#include "numerics/segment_distance.hpp"

namespace yarnhom::numerics {

struct CcdOptions {
  int max_iterations = 10000;  // advancement steps per pair (then the fraction reached is returned)
  double tolerance = 1e-6;     // stop once d - d_min < tolerance (d(0) - d_min): a contact
};

struct CcdResult {
  double t = 1;          // the move is safe on [0, t]: d >= d_min throughout (t = 1: the whole move)
  double d0 = 0;         // closest distance at the start
  int iterations = 0;    // distance evaluations
  bool hit() const { return t < 1; }
};

// q0, q1: the pair [a0, a1, b0, b1] at the start and at the end of the move. t = 0 when the
// start is already at or below d_min.
CcdResult segment_ccd(const Vec12& q0, const Vec12& q1, double dmin, const CcdOptions& opt = {});

// Conservative advancement along a straight move, given dist(t) (the pair's closest distance
// at the fraction t of the move, res.d0 = dist(0) already above `target`) and l, a bound on how
// fast the distance can shrink per unit t: steps of (d - target) / l never pass the target, so
// res.t is where the distance reaches it (to opt.tolerance of the gap), or 1 when it never does.
// What segment_ccd and the surface pairs' CCD (numerics/contact_pairs.hpp) share.
template <class Dist>
void advance(Dist&& dist, double target, double l, const CcdOptions& opt, CcdResult& res) {
  // Safe throughout when even the fastest approach cannot close the gap.
  if (res.d0 - l > target) return;
  const double stop = opt.tolerance * (res.d0 - target);
  double t = 0, d = res.d0;
  for (int it = 0; it < opt.max_iterations; ++it) {
    const double dt = (d - target) / l;  // [t, t + dt] is safe
    if (t + dt >= 1.0) {
      res.t = 1.0;
      return;
    }
    t += dt;
    d = dist(t);
    if (d - target <= stop) break;  // reached the target (to the tolerance): a contact at t
  }
  res.t = t;
}

// One segment's straight move: endpoints at the start and at the end.
struct SegmentMove {
  std::array<Eigen::Vector3d, 2> start, end;
};

// Candidate pairs (i in a, j in b) whose swept boxes (each segment's bounding box over its
// whole move) come within `reach` of each other: every pair that can come within `reach` at
// any time of the move is among them. From a hash grid over `a`: never all pairs.
std::vector<std::pair<int, int>> swept_pairs(const std::vector<SegmentMove>& a, const std::vector<SegmentMove>& b,
                                             double reach);

// The q0/q1 of segment_ccd for a pair of moves.
inline std::pair<Vec12, Vec12> pair_move(const SegmentMove& a, const SegmentMove& b) {
  Vec12 q0, q1;
  q0 << a.start[0], a.start[1], b.start[0], b.start[1];
  q1 << a.end[0], a.end[1], b.end[0], b.end[1];
  return {q0, q1};
}

}  // namespace yarnhom::numerics
