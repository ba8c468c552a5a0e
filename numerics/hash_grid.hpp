#pragma once
// Broad phase: which boxes may touch, without testing all pairs. One spatial hash for every
// contact and CCD search of the project (a yarn strip's segments, the RVE's periodic images,
// swept segments of a move).
//
// Boxes are binned into a uniform grid of cubic cells, hashed by their integer cell coordinates
// (21 bits each: cells are unique within +-1e6 cells of the origin, far more than any strip or
// tile spans; beyond that distinct cells may share a key, which only costs box tests), so the
// grid is unbounded and only occupied cells cost memory. With cells at least as large as the
// largest (inflated) box, each box touches at most 2 cells per axis, and the work is
// O(n + pairs) for boxes spread over space: never O(n^2).
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace yarnhom::numerics {

struct Box3 {
  Eigen::Vector3d lo, hi;
  bool overlaps(const Box3& o) const {
    return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all();
  }
};

class SpatialHash {
 public:
  // cell: the cells' edge length (> 0); expected: the number of boxes, to size the table.
  SpatialHash(double cell, size_t expected) : cell_(cell) { grid_.reserve(4 * expected); }

  // Enters box `id` (ids from 0) in every cell [lo, hi] touches.
  void insert(int id, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    if (id >= int(seen_.size())) seen_.resize(size_t(id) + 1, -1);
    for (int64_t x = cell_of(lo[0]); x <= cell_of(hi[0]); ++x)
      for (int64_t y = cell_of(lo[1]); y <= cell_of(hi[1]); ++y)
        for (int64_t z = cell_of(lo[2]); z <= cell_of(hi[2]); ++z) grid_[key(x, y, z)].push_back(id);
  }

  // Calls fn(id) once for every box entered in a cell that [lo, hi] touches, in a fixed order
  // (cells by x, then y, then z; within a cell, in insertion order). The caller tests the boxes.
  // below: only ids below it (the boxes entered in increasing id order, a cell's ids are
  // sorted: its scan stops at the first id at or above it; the same calls as skipping them).
  template <class Fn>
  void query(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, Fn&& fn, int below = INT32_MAX) {
    ++stamp_;
    for (int64_t x = cell_of(lo[0]); x <= cell_of(hi[0]); ++x)
      for (int64_t y = cell_of(lo[1]); y <= cell_of(hi[1]); ++y)
        for (int64_t z = cell_of(lo[2]); z <= cell_of(hi[2]); ++z) {
          const auto it = grid_.find(key(x, y, z));
          if (it == grid_.end()) continue;
          for (int id : it->second) {
            if (id >= below) break;
            if (seen_[size_t(id)] == stamp_) continue;
            seen_[size_t(id)] = stamp_;
            fn(id);
          }
        }
  }

 private:
  int64_t cell_of(double x) const { return static_cast<int64_t>(std::floor(x / cell_)); }
  static int64_t key(int64_t i, int64_t j, int64_t k) {
    return ((i & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (k & 0x1FFFFF);
  }
  double cell_;
  std::unordered_map<int64_t, std::vector<int>> grid_;
  std::vector<int> seen_;
  int stamp_ = 0;
};

// All pairs (i, j), i < j, of overlapping boxes (closed: touching counts), sorted.
// `cell`: the grid's cell size; 0 picks the largest box extent (at least 1e-12).
std::vector<std::pair<int, int>> overlapping_pairs(const std::vector<Box3>& boxes, double cell = 0);

}  // namespace yarnhom::numerics
