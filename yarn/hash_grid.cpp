#include "yarn/hash_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace yarnhom::yarn {

std::vector<std::pair<int, int>> overlapping_pairs(const std::vector<Box3>& boxes, double cell) {
  const int n = static_cast<int>(boxes.size());
  if (cell <= 0) {
    cell = 1e-12;
    for (const Box3& b : boxes) cell = std::max(cell, (b.hi - b.lo).maxCoeff());
  }
  const double inv = 1.0 / cell;
  auto cell_of = [&](const Eigen::Vector3d& x) {
    return Eigen::Vector3i(int(std::floor(x[0] * inv)), int(std::floor(x[1] * inv)), int(std::floor(x[2] * inv)));
  };
  // 21 bits per coordinate: cells are unique within +-1e6 cells of the origin, far more than
  // any strip spans; beyond that distinct cells may share a key, which only costs box tests.
  auto key = [](const Eigen::Vector3i& c) {
    return (uint64_t(c[0] & 0x1FFFFF) << 42) | (uint64_t(c[1] & 0x1FFFFF) << 21) | uint64_t(c[2] & 0x1FFFFF);
  };
  struct Entry {
    uint64_t key;
    int box;
  };
  std::vector<Entry> entries;
  entries.reserve(4 * size_t(n));
  std::vector<Eigen::Vector3i> lo_cell(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3i a = cell_of(boxes[i].lo), b = cell_of(boxes[i].hi);
    lo_cell[i] = a;
    for (int x = a[0]; x <= b[0]; ++x)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int z = a[2]; z <= b[2]; ++z) entries.push_back({key({x, y, z}), i});
  }
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.key < b.key || (a.key == b.key && a.box < b.box); });
  std::vector<std::pair<int, int>> pairs;
  for (size_t s = 0; s < entries.size();) {
    size_t e = s;
    while (e < entries.size() && entries[e].key == entries[s].key) ++e;
    for (size_t i = s; i < e; ++i)
      for (size_t j = i + 1; j < e; ++j) {
        const int a = entries[i].box, b = entries[j].box;
        if (!boxes[a].overlaps(boxes[b])) continue;
        // Report the pair only in the cell of the intersection's lowest corner.
        if (key(lo_cell[a].cwiseMax(lo_cell[b])) != entries[s].key) continue;
        pairs.emplace_back(a, b);
      }
    s = e;
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace yarnhom::yarn
