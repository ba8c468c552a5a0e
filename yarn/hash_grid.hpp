#pragma once
// Broad phase: which pairs of axis-aligned boxes overlap, without testing all pairs.
//
// The boxes are binned into a uniform grid of cubic cells (hashed by their integer cell
// coordinates, so the grid is unbounded and only occupied cells cost memory); two boxes can
// overlap only if they share a cell. Each overlapping pair is reported once: by the cell that
// holds the lowest corner of the two boxes' intersection. With cells at least as large as the
// largest box, each box touches at most 2 cells per axis, and the work is O(n + pairs) for
// boxes spread over space (a yarn strip, a periodic tile): never O(n^2).
#include <Eigen/Core>
#include <utility>
#include <vector>

namespace yarnhom::yarn {

struct Box3 {
  Eigen::Vector3d lo, hi;
  bool overlaps(const Box3& o) const {
    return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all();
  }
};

// All pairs (i, j), i < j, of overlapping boxes (closed: touching counts), sorted.
// `cell`: the grid's cell size; 0 picks the largest box extent (at least 1e-12).
std::vector<std::pair<int, int>> overlapping_pairs(const std::vector<Box3>& boxes, double cell = 0);

}  // namespace yarnhom::yarn
