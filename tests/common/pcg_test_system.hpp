#pragma once
// A cloth-like test system for the block-Jacobi PCG twins (tests/numerics, tests/cuda): n x n
// vertices on a grid, 3 unknowns each, A = mass I + sum over the grid's edges and diagonals of
// [K -K; -K K] with K a random symmetric positive definite 3 x 3 of size `stiffness` (fixed
// seed). Symmetric positive definite; lower triangle, compressed.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <cstdlib>
#include <random>
#include <vector>

namespace yarnhom::test {

inline Eigen::SparseMatrix<double> pcg_test_system(int n, double mass, double stiffness) {
  std::mt19937 rng(17);
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
      for (auto [di, dj] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}}) {
        if (i + di >= n || j + dj >= n) continue;
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

// The shell's stencil on the same kind of grid (benchmarks: tools/bench/bench_sim.cpp and
// bench_cuda.cpp): every vertex coupled to its two-ring, the 18 vertices within two steps on the
// triangulated grid (offsets (di, dj) with |di|, |dj|, |di + dj| <= 2), as a bending element's
// flaps couple them: 19 blocks, 57 entries a row, a T-shirt's rows at side 121 (43,923 unknowns).
inline Eigen::SparseMatrix<double> pcg_shell_system(int n, double mass, double stiffness) {
  std::mt19937 rng(23);
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
      for (int dj = 0; dj <= 2; ++dj)
        for (int di = -2; di <= 2; ++di) {
          if ((dj == 0 && di <= 0) || std::abs(di + dj) > 2) continue;  // each pair once
          if (i + di < 0 || i + di >= n || j + dj >= n) continue;
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

}  // namespace yarnhom::test
