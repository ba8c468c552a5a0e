// The spatial hash every broad phase uses: a query visits each box entered in the cells it
// touches exactly once (so no candidate is lost and none is tested twice), whatever the cell
// size, and boxes far from the query box are not visited when cells are small; the pairs of
// overlapping boxes it finds are exactly the brute-force ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "numerics/hash_grid.hpp"

using namespace yarnhom::numerics;

TEST(SpatialHash, QueryVisitsEveryOverlappingBoxOnce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1), S(0.01, 0.2);
  std::vector<Box3> boxes(300);
  for (auto& b : boxes) {
    b.lo = Eigen::Vector3d(U(rng), U(rng), U(rng));
    b.hi = b.lo + Eigen::Vector3d(S(rng), S(rng), S(rng));
  }
  for (double cell : {0.05, 0.2, 1.0, 5.0}) {
    SpatialHash grid(cell, boxes.size());
    for (int i = 0; i < int(boxes.size()); ++i) grid.insert(i, boxes[i].lo, boxes[i].hi);
    for (int q = 0; q < 50; ++q) {
      Box3 probe;
      probe.lo = Eigen::Vector3d(U(rng), U(rng), U(rng));
      probe.hi = probe.lo + Eigen::Vector3d(S(rng), S(rng), S(rng));
      std::vector<int> visited;
      grid.query(probe.lo, probe.hi, [&](int id) { visited.push_back(id); });
      std::vector<int> sorted = visited;
      std::sort(sorted.begin(), sorted.end());
      EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "a box visited twice";
      for (int i = 0; i < int(boxes.size()); ++i)
        if (boxes[i].overlaps(probe))
          EXPECT_TRUE(std::binary_search(sorted.begin(), sorted.end(), i)) << "missed box " << i << ", cell " << cell;
      if (cell == 0.05) EXPECT_LT(visited.size(), boxes.size() / 4) << "a small-cell query visits only nearby boxes";
    }
  }
}

TEST(HashGrid, FindsExactlyTheOverlappingPairs) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0, 1), S(0.01, 0.15);
  std::vector<Box3> boxes(400);
  for (auto& b : boxes) {
    b.lo = Eigen::Vector3d(U(rng), U(rng), 0.2 * U(rng));
    b.hi = b.lo + Eigen::Vector3d(S(rng), S(rng), S(rng));
  }
  boxes[7] = boxes[3];  // identical boxes overlap
  std::vector<std::pair<int, int>> brute;
  for (int i = 0; i < int(boxes.size()); ++i)
    for (int j = i + 1; j < int(boxes.size()); ++j)
      if (boxes[i].overlaps(boxes[j])) brute.emplace_back(i, j);
  for (double cell : {0.0, 0.05, 0.3}) EXPECT_EQ(overlapping_pairs(boxes, cell), brute) << "cell " << cell;
  EXPECT_GT(brute.size(), 100u);
}
