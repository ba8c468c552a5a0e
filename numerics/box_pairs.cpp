#include "numerics/box_pairs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "core/raw_vector.hpp"
#include "core/scope_profile.hpp"
#include "numerics/radix_sort.hpp"

namespace yarnhom::numerics {

namespace {

// The cells of a uniform grid over `a`'s boxes (origin at their lower corner): box i's cell range
// [c0, c1] per axis; cell (x, y, z) holds, in increasing order, the boxes whose range contains it
// (start[cell] .. start[cell + 1] in ids).
struct DenseGrid {
  Eigen::Vector3d cell = Eigen::Vector3d::Ones();
  Eigen::Vector3d origin;
  std::array<int64_t, 3> n{1, 1, 1};
  RawVector<std::array<int, 6>> range;  // per box of a: x0 y0 z0 x1 y1 z1 (x1 < x0: not entered)
  RawVector<int> start, ids;

  int64_t coord(double v, int axis) const {
    const double c = std::floor((v - origin[axis]) / cell[axis]);
    return int64_t(std::clamp(c, 0.0, double(n[size_t(axis)] - 1)));
  }
  int64_t index(int64_t x, int64_t y, int64_t z) const { return (z * n[1] + y) * n[0] + x; }
};

bool finite_box(const Box3& x) { return x.lo.allFinite() && x.hi.allFinite(); }

// From this many boxes the grid's counting sort runs on the OpenMP threads.
constexpr int64_t kParallelBoxes = 8192;

// Cells, per axis, as long as the larger boxes of a along it (the 90th percentile's extent, so
// one long box does not coarsen the grid for all; per axis, so boxes stretched along one
// direction -- a falling sheet's moves -- keep cells of a triangle's size across it), no box of
// a or b spanning more than 8 cells along an axis, and no more cells than about 4 per box of a
// (for boxes spread far apart: the grid then coarsens, which costs box tests, not results). The
// cap coarsens the smallest cells first: a flat sheet's boxes are thin across it, and merging
// those thin cells costs nothing, while coarsening all axes alike (as this did before) made the
// cells along the sheet, which set how many boxes share a cell, 2-3 times a triangle's size (a
// T-shirt's panels: 350-570 boxes met per query for 8 overlaps, now about 4 times fewer).
DenseGrid make_grid(const std::vector<Box3>& a, const std::vector<Box3>& b) {
  DenseGrid g;
  const int64_t na = int64_t(a.size()), nb = int64_t(b.size());
  const bool par = na >= kParallelBoxes;
  std::optional<prof::Scope> phase(std::in_place, "box_pairs: grid, its cells");
  // The finite boxes' bounds, and the largest extents of a and b per axis (over 8 below).
  double l0 = INFINITY, l1 = INFINITY, l2 = INFINITY, h0 = -INFINITY, h1 = -INFINITY, h2 = -INFINITY;
  double m0 = 0, m1 = 0, m2 = 0;
  int64_t finite = 0;
#pragma omp parallel for schedule(static) if (na + nb >= kParallelBoxes) reduction(min : l0, l1, l2) reduction(max : h0, h1, h2, m0, m1, m2) \
    reduction(+ : finite)
  for (int64_t i = 0; i < na + nb; ++i) {
    const Box3& x = i < na ? a[size_t(i)] : b[size_t(i - na)];
    if (!finite_box(x)) continue;
    m0 = std::max(m0, x.hi[0] - x.lo[0]), m1 = std::max(m1, x.hi[1] - x.lo[1]), m2 = std::max(m2, x.hi[2] - x.lo[2]);
    if (i >= na) continue;
    ++finite;
    l0 = std::min(l0, x.lo[0]), l1 = std::min(l1, x.lo[1]), l2 = std::min(l2, x.lo[2]);
    h0 = std::max(h0, x.hi[0]), h1 = std::max(h1, x.hi[1]), h2 = std::max(h2, x.hi[2]);
  }
  const Eigen::Vector3d lo(l0, l1, l2), hi(h0, h1, h2);
  g.range.resize(a.size());  // (each box's range set by the counting pass below)
  if (finite == 0) {
    g.range.assign(a.size(), {0, 0, 0, -1, -1, -1});
    g.start.assign(2, 0);
    return g;
  }
  // The 90th percentile of a's extents per axis, over a sample of about 4,096 of its boxes
  // (every stride-th, the finite ones: the cell size needs the scale, not the exact quantile).
  const int64_t stride = std::max<int64_t>(1, na / 4096);
  std::array<std::vector<double>, 3> ext;
  for (auto& e : ext) e.reserve(size_t(na / stride + 1));
  for (int64_t i = 0; i < na; i += stride)
    if (finite_box(a[size_t(i)]))
      for (int d = 0; d < 3; ++d) ext[size_t(d)].push_back(a[size_t(i)].hi[d] - a[size_t(i)].lo[d]);
  if (ext[0].empty())  // (the sample met only boxes that are not finite: take the first finite one)
    for (const Box3& x : a)
      if (finite_box(x)) {
        for (int d = 0; d < 3; ++d) ext[size_t(d)].push_back(x.hi[d] - x.lo[d]);
        break;
      }
  Eigen::Vector3d cell;
  for (int d = 0; d < 3; ++d) {
    std::vector<double>& e = ext[size_t(d)];
    const size_t k = std::min(e.size() - 1, e.size() * 9 / 10);
    std::nth_element(e.begin(), e.begin() + k, e.end());
    cell[d] = std::max(e[k], 1e-9);
  }
  cell = cell.cwiseMax(Eigen::Vector3d(m0, m1, m2) / 8);
  const double cap = 4.0 * double(a.size()) + 64;
  const Eigen::Vector3d span = hi - lo;
  for (;;) {
    const Eigen::Vector3d cells = (span.array() / cell.array()).floor() + 1;
    const double total = cells.prod();
    if (total <= cap) {
      for (int d = 0; d < 3; ++d) g.n[size_t(d)] = int64_t(cells[d]);
      break;
    }
    // The smallest cells coarsen first, towards the next larger ones.
    int d = 0;
    cell.minCoeff(&d);
    double next = INFINITY;
    for (int e = 0; e < 3; ++e)
      if (e != d) next = std::min(next, cell[e]);
    cell[d] *= std::clamp(std::min(total / cap, next / cell[d]), 1.01, 1e12);
  }
  g.cell = cell;
  g.origin = lo;
  const size_t ncell = size_t(g.n[0] * g.n[1] * g.n[2]);
  phase.emplace("box_pairs: grid, counts");
  // Each box's cell range and its number of cells, on the threads; their running sum places box
  // i's cells at [off[i], off[i + 1]) of the list of (cell, box) entries.
  std::vector<int64_t> off(size_t(na) + 1);
  off[0] = 0;
#pragma omp parallel for schedule(static) if (par)
  for (int64_t i = 0; i < na; ++i) {
    auto& r = g.range[size_t(i)];
    if (!finite_box(a[size_t(i)])) {
      r = {0, 0, 0, -1, -1, -1};
      off[size_t(i) + 1] = 0;
      continue;
    }
    for (int d = 0; d < 3; ++d) {
      r[size_t(d)] = int(g.coord(a[size_t(i)].lo[d], d));
      r[size_t(d) + 3] = int(g.coord(a[size_t(i)].hi[d], d));
    }
    off[size_t(i) + 1] = int64_t(r[3] - r[0] + 1) * (r[4] - r[1] + 1) * (r[5] - r[2] + 1);
  }
  for (int64_t i = 0; i < na; ++i) off[size_t(i) + 1] += off[size_t(i)];
  phase.emplace("box_pairs: grid, boxes entered");
  // The entries in box order, then sorted by cell, stably: each cell's boxes in increasing order.
  const size_t total = size_t(off[size_t(na)]);
  RawVector<uint32_t> key(total);
  g.ids.resize(total);
#pragma omp parallel for schedule(static) if (par)
  for (int64_t i = 0; i < na; ++i) {
    const auto& r = g.range[size_t(i)];
    size_t k = size_t(off[size_t(i)]);
    for (int64_t z = r[2]; z <= r[5]; ++z)
      for (int64_t y = r[1]; y <= r[4]; ++y)
        for (int64_t x = r[0]; x <= r[3]; ++x, ++k) {
          key[k] = uint32_t(g.index(x, y, z));
          g.ids[k] = int(i);
        }
  }
  radix_sort(key, g.ids, key_bits(uint64_t(ncell)), par && total >= size_t(kParallelBoxes));
  phase.emplace("box_pairs: grid, cells' starts");
  // start[c]: the first entry of cell c or after; the entry where the cell changes writes the
  // starts of the cells from the last entry's cell (exclusive) to its own.
  g.start.resize(ncell + 1);
#pragma omp parallel for schedule(static) if (par)
  for (int64_t k = 0; k < int64_t(total); ++k) {
    const size_t c = key[size_t(k)], from = k > 0 ? size_t(key[size_t(k) - 1]) + 1 : 0;
    for (size_t q = from; q <= c; ++q) g.start[q] = int(k);
  }
  for (size_t q = total > 0 ? size_t(key[total - 1]) + 1 : 0; q <= ncell; ++q) g.start[q] = int(total);
  return g;
}

}  // namespace

std::vector<std::pair<int, int>> box_pairs(const std::vector<Box3>& a, const std::vector<Box3>& b, bool same,
                                           const std::function<bool(int, int)>& keep) {
  std::vector<std::pair<int, int>> out;
  if (a.empty() || b.empty()) return out;
  prof::Scope ps("box_pairs");
  const DenseGrid g = [&] {
    prof::Scope pg("box_pairs: grid");
    return make_grid(a, b);
  }();
  // Boxes with a coordinate that is not finite (an infinite box overlaps others, a NaN box
  // none) are tested against all boxes of the other set.
  std::vector<int> odd_a;
  for (size_t i = 0; i < a.size(); ++i)
    if (!finite_box(a[i])) odd_a.push_back(int(i));
  // Queries: b's boxes in chunks, a fixed number per chunk whatever the thread count, each chunk's
  // pairs in their own list, the lists joined in order: the same result for any thread count.
  // A pair is reported once, from the first cell both boxes' ranges share (per axis the larger
  // of their first cells); each box's pairs are sorted by i.
  // Small chunks: the pairs crowd where layers of cloth meet, so a chunk of a few thousand boxes
  // (a sleeve's edges) could hold most of the work and leave the other threads idle.
  constexpr int kChunk = 256, kParallelMin = 4096;
  const int nb = int(b.size()), nchunks = (nb + kChunk - 1) / kChunk;
  std::vector<std::vector<std::pair<int, int>>> part(static_cast<size_t>(nchunks));
  {
    prof::Scope pq("box_pairs: queries");
#pragma omp parallel for schedule(dynamic, 1) if (nb >= kParallelMin)
    for (int c = 0; c < nchunks; ++c) {
      std::vector<std::pair<int, int>>& o = part[size_t(c)];
      std::vector<int> hit;
      for (int j = c * kChunk; j < std::min(nb, (c + 1) * kChunk); ++j) {
        const Box3& q = b[size_t(j)];
        const int below = same ? j : INT32_MAX;
        hit.clear();
        if (finite_box(q)) {
          int64_t r[6];
          for (int d = 0; d < 3; ++d) r[d] = g.coord(q.lo[d], d), r[d + 3] = g.coord(q.hi[d], d);
          for (int64_t z = r[2]; z <= r[5]; ++z)
            for (int64_t y = r[1]; y <= r[4]; ++y)
              for (int64_t x = r[0]; x <= r[3]; ++x) {
                const size_t cell = size_t(g.index(x, y, z));
                for (int k = g.start[cell]; k < g.start[cell + 1]; ++k) {
                  const int i = g.ids[size_t(k)];
                  if (i >= below) break;
                  const auto& ri = g.range[size_t(i)];
                  if (std::max<int64_t>(ri[0], r[0]) != x || std::max<int64_t>(ri[1], r[1]) != y ||
                      std::max<int64_t>(ri[2], r[2]) != z)
                    continue;  // reported from another cell
                  if (a[size_t(i)].overlaps(q)) hit.push_back(i);
                }
              }
          for (int i : odd_a)
            if (i < below && a[size_t(i)].overlaps(q)) hit.push_back(i);
        } else {
          for (int i = 0; i < std::min<int>(int(a.size()), below); ++i)
            if (a[size_t(i)].overlaps(q)) hit.push_back(i);
        }
        std::sort(hit.begin(), hit.end());
        for (int i : hit)
          if (!keep || keep(i, j)) o.emplace_back(i, j);
      }
    }
  }
  prof::Scope pj("box_pairs: lists joined");
  size_t total = 0;
  for (const auto& p : part) total += p.size();
  out.reserve(total);
  for (const auto& p : part) out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace yarnhom::numerics
