#pragma once
// The broad phase's pair search: which boxes of one set overlap which boxes of another (the
// contact pairs' candidates of both simulators, numerics/contact_pairs.hpp).
//
// A uniform grid over a's boxes: each box entered in every cell its range touches (a stable
// radix sort of (cell, box) entries, numerics/radix_sort.hpp, on the OpenMP threads: each cell's
// boxes in increasing order), b's boxes querying the cells they touch; a pair is reported once,
// from the first cell both boxes' ranges share.
#include <functional>
#include <utility>
#include <vector>

#include "numerics/hash_grid.hpp"

namespace yarnhom::numerics {

// Pairs (i, j), i indexing `a` and j indexing `b`, whose boxes overlap (closed), each pair once,
// sorted by j, then i. When `same` is true, a and b are one set: only i < j. The queries run on
// the OpenMP threads in fixed chunks (the result does not depend on the thread count). Boxes
// with a coordinate that is not finite are tested against every box of the other set. keep (if
// given): a pair is returned only if keep(i, j) (called for the overlapping pairs, from the
// threads at once).
std::vector<std::pair<int, int>> box_pairs(const std::vector<Box3>& a, const std::vector<Box3>& b, bool same = false,
                                           const std::function<bool(int, int)>& keep = {});

}  // namespace yarnhom::numerics
