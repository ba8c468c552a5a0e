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
// result is therefore the fresh broad phase's pair set exactly (the order may differ: the
// region's hash order, with the obstacles' primitives hashed and the cloth's querying), and in
// particular the same pairs within d_min + dhat. A query that is not covered rebuilds the
// region over its own move, grown by a margin (dhat / 10). In a step,
// one region over x_n -> the prediction serves the step start, the friction lag and the Newton
// matrix, and one over x -> x + p (the CCD of the Newton step) serves every line-search trial
// x + alpha p, alpha in [0, 1]: fl(x + alpha p) lies between x and fl(x + p) per coordinate,
// rounding being monotone.
#include <Eigen/Core>
#include <array>
#include <vector>

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

// A broad phase kept over a region (see above). Use one per step (StepState::contact_cache):
// the region follows the queries.
class ContactCache {
 public:
  // The pairs of contact_candidates(P, x0, x1, y0, y1), as a set.
  std::vector<ContactPair> candidates(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& x1,
                                      const Eigen::VectorXd& y0, const Eigen::VectorXd& y1);
  int builds() const { return builds_; }    // spatial hashes built
  int queries() const { return queries_; }  // queries answered (built or reused)
  size_t region_pairs() const { return entries_.size(); }

 private:
  struct Entry {
    unsigned char group;
    int i, j;
  };
  bool covers(const Eigen::VectorXd& lo, const Eigen::VectorXd& hi, const Eigen::VectorXd& p) const;
  Eigen::VectorXd xlo_, xhi_, ylo_, yhi_;
  std::vector<Entry> entries_;
  bool valid_ = false;
  int builds_ = 0, queries_ = 0;
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
