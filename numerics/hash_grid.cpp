#include "numerics/hash_grid.hpp"

#include <algorithm>

namespace yarnhom::numerics {

std::vector<std::pair<int, int>> overlapping_pairs(const std::vector<Box3>& boxes, double cell) {
  const int n = static_cast<int>(boxes.size());
  if (cell <= 0) {
    cell = 1e-12;
    for (const Box3& b : boxes) cell = std::max(cell, (b.hi - b.lo).maxCoeff());
  }
  SpatialHash grid(cell, boxes.size());
  for (int i = 0; i < n; ++i) grid.insert(i, boxes[i].lo, boxes[i].hi);
  std::vector<std::pair<int, int>> pairs;
  for (int j = 0; j < n; ++j)
    grid.query(
        boxes[j].lo, boxes[j].hi,
        [&](int i) {
          if (boxes[i].overlaps(boxes[j])) pairs.emplace_back(i, j);
        },
        j);  // i < j
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace yarnhom::numerics
