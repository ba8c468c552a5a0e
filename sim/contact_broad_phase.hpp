#pragma once
// The broad phase of the cloth's contact pairs (sim/contact.hpp): which point-triangle and
// edge-edge pairs a contact evaluation or a CCD tests, and a cache that serves one step's many
// evaluations from one spatial hash.
//
// Fresh (contact_candidates without a cache): boxes of the cloth's vertices, triangles and
// edges and of the obstacles' primitives over the move x0 -> x1 (y0 -> y1), inflated by
// dhat / 2 (obstacle points and edges also by their capsule radius), and the pairs whose boxes
// overlap (numerics::box_pairs), less the self pairs sharing a (stitched) vertex. A pair within
// d_min + dhat anywhere on the move has overlapping boxes: the L-inf distance of two boxes
// never exceeds the Euclidean distance of points in them.
//
// Cached (ContactCache): a region R, per cloth vertex v the box [lo_v, hi_v] (per obstacle
// point likewise), and the pairs whose primitives' region boxes overlap: the box of a
// primitive over R is the union of its vertices' region boxes, inflated as above. A query
// (x0 -> x1, y0 -> y1) whose every vertex lies in its region box at both ends (covered) has, for
// each primitive, a move box inside the primitive's region box (inflation equal), so every
// pair whose move boxes overlap is among the region's pairs; the query keeps those of them
// whose move boxes overlap, by the same floating-point test as the fresh broad phase. The
// result is therefore the fresh broad phase's pairs exactly, in the same order (by group, then
// the two primitives' indices: numerics::box_pairs sorts its pairs, so the order depends on
// neither the region nor the grid's cells), and in particular the same pairs within d_min + dhat. A query that is not covered rebuilds the
// region over its own move, grown by a margin (dhat / 10). In a step,
// one region over x_n -> the prediction serves the step start, the friction lag and the Newton
// matrix, and one over x -> x + p (the CCD of the Newton step) serves every line-search trial
// x + alpha p, alpha in [0, 1]: fl(x + alpha p) lies between x and fl(x + p) per coordinate,
// rounding being monotone.
//
// Near pairs (ContactCache::near, ::ccd_candidates): most of a region's pairs are far apart (a
// flat sheet's neighbours beyond the shared vertices: their boxes overlap, their distance is a
// triangle's size), and their barrier, friction and CCD are exactly those of no pair. The cache
// keeps, per region pair, a lower bound g of its distance less d_min at the positions of its
// last near or CCD query (the snapshot), and carries it to the next query's positions by the
// CCD's speed bound (numerics/contact_pairs.hpp: contact_speed): on the straight move between
// the two, the pair's distance changes by at most l = contact_speed(dq), dq its points' moves,
// so g - l bounds it at the new positions (a common translation costs nothing: a falling
// sheet's neighbours keep their bound). A pair whose bound is below what the query needs gets
// its distance computed exactly (and g is that). The query needs, with a margin m = 1e-4 dhat
// (far above the round-off of a distance or a bound at the coordinates of a scene):
//   near at (x, y): g >= dhat + m, then d >= d_min + dhat: its barrier and friction are zero;
//   CCD of (x0 -> x1): 0.9 (g - f) - l >= m at x0, f = 0 (kObstacleFloor dhat with an obstacle
//   point), l its speed bound over the move: contact_ccd's first test, d0 - l > d_min + eta
//   (d0 - d_min) (and the floor's), then returns t = 1.
// The other region pairs go through the broad phase's own box test at the query's positions,
// so the result is the candidates' list with pairs left out and nothing else changed: the
// barrier's sum, its gradient and triplets, the CCD bound and its hits come out bit for bit.
// A rebuild keeps the snapshot: a pair of the old region keeps its bound (it bounds the pair's
// distance at the snapshot's positions, whatever the region), a new pair has none and is
// computed at its first query; the cache's first build computes every pair once.
#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/raw_vector.hpp"
#include "numerics/contact_distance.hpp"
#include "numerics/hash_grid.hpp"
#include "sim/problem.hpp"

namespace yarnhom::sim {

struct ContactPair {
  numerics::ContactKind kind = numerics::ContactKind::PointTriangle;
  std::array<int, 4> slot{};  // cloth vertex >= 0; obstacle point k as -1 - k
  double dmin = 0;            // m: capsule radius, else 0
  double mu = 0;              // friction coefficient of the pair
};

// Box of points idx[0 .. n) of p0 and p1 (3 per point), inflated by reach.
template <class Idx>
numerics::Box3 move_box(const Idx& idx, int n, const Eigen::VectorXd& p0, const Eigen::VectorXd& p1, double reach) {
  numerics::Box3 b{p0.segment<3>(3 * idx[0]), p0.segment<3>(3 * idx[0])};
  for (int i = 0; i < n; ++i)
    for (const Eigen::VectorXd* p : {&p0, &p1}) {
      b.lo = b.lo.cwiseMin(p->segment<3>(3 * idx[i]));
      b.hi = b.hi.cwiseMax(p->segment<3>(3 * idx[i]));
    }
  b.lo.array() -= reach;
  b.hi.array() += reach;
  return b;
}

// The vertex's representative: stitched vertices count as one (Problem::vertex_rep).
inline int vertex_rep(const Problem& P, int v) { return P.vertex_rep.empty() ? v : P.vertex_rep[v]; }

// contact_step_bound's CCD (sim/contact.hpp): the gap it may close (1 - eta of it), the
// floor of a pair with obstacle points, d_min + this times dhat, and the share of its gap that
// such a pair within the floor may lose on a move (its obstacle's rounding).
inline constexpr double kContactEta = 0.1;
inline constexpr double kObstacleFloor = 0.1;
inline constexpr double kFloorCreep = 1e-3;

// A broad phase kept over a region (see above). The simulation keeps one from step to step
// (ObstacleMotion::contact_cache, sim/integrators.hpp): the region follows the queries, and the
// pairs' bounds carry over from one step's last query to the next step's first (a bound of a
// pair's distance at the snapshot's positions holds whatever the step), so a step's first region
// computes only the distances its moves require, not every pair's.
class ContactCache {
 public:
  // The pairs of contact_candidates(P, x0, x1, y0, y1), as a set.
  std::vector<ContactPair> candidates(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                                      const Eigen::VectorXd& y0, const Eigen::VectorXd& y1);
  // The pairs of candidates(P, x, x, y, y), in its order, less pairs shown to lie farther than
  // d_min + P.dhat apart ("Near pairs" above): every one within it, whose barrier and friction
  // are not zero, is among them.
  std::vector<ContactPair> near(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& y);
  // The pairs of candidates(P, x0, x1, y0, y1), in its order, less pairs shown to stay safe on
  // the whole move: contact_ccd with eta = kContactEta gives them t = 1 (a pair with an obstacle
  // point also at the floor d_min + kObstacleFloor dhat), so contact_step_bound's fraction and
  // hits are those of all the candidates.
  std::vector<ContactPair> ccd_candidates(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                                          const Eigen::VectorXd& y0, const Eigen::VectorXd& y1);
  int builds() const { return builds_; }    // spatial hashes built
  int queries() const { return queries_; }  // queries answered (built or reused)
  size_t region_pairs() const { return entries_.size(); }
  long distances() const { return distances_; }  // pair distances computed by near and ccd_candidates

 private:
  // A region pair: its group and the two primitives (its ContactPair made from them when needed:
  // a small entry, written on the threads at a build and read at every query).
  struct Entry {
    unsigned char group;
    int i, j;
  };
  ContactPair pair_of(const Problem& P, const Entry& e) const;
  bool covers(const Eigen::VectorXd& lo, const Eigen::VectorXd& hi, const Eigen::VectorXd& p) const;
  // Builds the region over the move unless it covers both ends.
  void cover(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1, const Eigen::VectorXd& y0,
             const Eigen::VectorXd& y1);
  bool entry_overlaps(const Problem& P, const Entry& e, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                      const Eigen::VectorXd& y0, const Eigen::VectorXd& y1) const;
  Eigen::VectorXd xlo_, xhi_, ylo_, yhi_;
  RawVector<Entry> entries_;
  std::vector<double> radius_;  // obstacle points' capsule radius
  bool valid_ = false;
  int builds_ = 0, queries_ = 0;
  // Near pairs: per entry a lower bound of (its distance - d_min) at (sx_, sy_), when snapped_.
  Eigen::VectorXd sx_, sy_;
  RawVector<double> gap_;
  bool snapped_ = false;
  bool sorted_ = false;  // entries_ is in (group, j, i) order (checked at each build)
  long distances_ = 0;
};

// Candidate pairs over the move x0 -> x1 (cloth, 3n) and y0 -> y1 (obstacles, 3K); x1 = x0 and
// y1 = y0 for a static search. With a cache: the same set, from the cache's region.
std::vector<ContactPair> contact_candidates(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                                            const Eigen::VectorXd& y0, const Eigen::VectorXd& y1,
                                            ContactCache* cache = nullptr);

// The pairs whose boxes at (x, y), inflated by reach / 2 (obstacle points and edges also by
// their radius), overlap: every pair within d_min + reach, and more (a wider net than dhat's).
std::vector<ContactPair> contact_candidates_within(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& y,
                                                   double reach);

}  // namespace yarnhom::sim
