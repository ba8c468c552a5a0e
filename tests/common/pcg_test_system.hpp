#pragma once
// Cloth-like test systems for the block-Jacobi PCG twins (tests/numerics, tests/cuda, and the
// benchmarks tools/bench/bench_sim.cpp and bench_cuda.cpp): n x n vertices on a grid, 3 unknowns
// each, A = mass I + sum over coupled vertex pairs of [K -K; -K K] with K a random symmetric
// positive definite 3 x 3 of size `stiffness` (fixed seed). Symmetric positive definite; lower
// triangle, compressed.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <cstdlib>
#include <random>
#include <utility>
#include <vector>

namespace yarnhom::test {

// The system whose vertex (i, j) is coupled to (i + di, j + dj) for each offset, in the order
// given (each pair once: the offsets point one way), the random blocks drawn in that order.
inline Eigen::SparseMatrix<double> grid_pair_system(int n, double mass, double stiffness, unsigned seed,
                                                    const std::vector<std::pair<int, int>>& offsets) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  auto id = [n](int i, int j) { return j * n + i; };
  auto add_block = [&](int a, int b, const Eigen::Matrix3d& K) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        if (3 * a + r >= 3 * b + c) t.emplace_back(3 * a + r, 3 * b + c, K(r, c));
  };
  for (int v = 0; v < n * n; ++v) add_block(v, v, mass * Eigen::Matrix3d::Identity());
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      for (const auto& [di, dj] : offsets) {
        if (i + di < 0 || i + di >= n || j + dj < 0 || j + dj >= n) continue;
        Eigen::Matrix3d G;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) G(r, c) = u(rng);
        const Eigen::Matrix3d K = stiffness * (G * G.transpose() + 0.1 * Eigen::Matrix3d::Identity());
        const int a = std::max(id(i, j), id(i + di, j + dj)), b = std::min(id(i, j), id(i + di, j + dj));
        add_block(a, a, K);
        add_block(b, b, K);
        add_block(a, b, -K);
      }
  Eigen::SparseMatrix<double> L(3 * n * n, 3 * n * n);
  L.setFromTriplets(t.begin(), t.end());
  L.makeCompressed();
  return L;
}

// The grid's edges and diagonals (7 blocks a block row).
inline Eigen::SparseMatrix<double> pcg_test_system(int n, double mass, double stiffness) {
  return grid_pair_system(n, mass, stiffness, 17, {{1, 0}, {0, 1}, {1, 1}});
}

// The shell's stencil: every vertex coupled to its two-ring, the 18 vertices within two steps
// on the triangulated grid (offsets (di, dj) with |di|, |dj|, |di + dj| <= 2), as a bending
// element's flaps couple them: 19 blocks, 57 entries a row, a T-shirt's rows at side 121
// (43,923 unknowns).
inline Eigen::SparseMatrix<double> pcg_shell_system(int n, double mass, double stiffness) {
  std::vector<std::pair<int, int>> offsets;
  for (int dj = 0; dj <= 2; ++dj)
    for (int di = -2; di <= 2; ++di)
      if (!(dj == 0 && di <= 0) && std::abs(di + dj) <= 2) offsets.emplace_back(di, dj);
  return grid_pair_system(n, mass, stiffness, 23, offsets);
}

}  // namespace yarnhom::test
