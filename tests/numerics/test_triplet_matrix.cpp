// numerics/triplet_matrix.hpp: the matrix Eigen's setFromTriplets makes, bit for bit (the same
// pattern, each duplicate summed in the triplets' order), on any number of threads.
#include <gtest/gtest.h>
#include <omp.h>

#include <random>

#include "numerics/triplet_matrix.hpp"

using namespace yarnhom;

namespace {

// Triplets with many duplicates (each entry hit up to 8 times, in scattered order), values of
// very different magnitudes so that the order of a sum shows in its last bits.
std::vector<Eigen::Triplet<double>> random_triplets(int n, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> idx(0, n - 1), few(0, n / 7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < count; ++k) {
    const int r = k % 3 == 0 ? few(rng) : idx(rng), c = k % 5 == 0 ? few(rng) : idx(rng);
    t.emplace_back(r, c, u(rng) * std::pow(10.0, double(k % 9) - 4));
  }
  return t;
}

void expect_identical(const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& b) {
  ASSERT_EQ(a.rows(), b.rows());
  ASSERT_EQ(a.cols(), b.cols());
  ASSERT_TRUE(a.isCompressed());
  ASSERT_TRUE(b.isCompressed());
  ASSERT_EQ(a.nonZeros(), b.nonZeros());
  for (Eigen::Index c = 0; c <= a.outerSize(); ++c) ASSERT_EQ(a.outerIndexPtr()[c], b.outerIndexPtr()[c]) << "column " << c;
  for (Eigen::Index k = 0; k < a.nonZeros(); ++k) {
    ASSERT_EQ(a.innerIndexPtr()[k], b.innerIndexPtr()[k]) << "entry " << k;
    ASSERT_EQ(a.valuePtr()[k], b.valuePtr()[k]) << "entry " << k;  // bit for bit
  }
}

}  // namespace

TEST(TripletMatrix, IsSetFromTripletsBitForBitOnAnyThreadCount) {
  const int saved = omp_get_max_threads();
  for (const auto& [n, count] : {std::pair{40, 300}, std::pair{3000, 200000}}) {
    const auto t = random_triplets(n, count, 5u + unsigned(n));
    Eigen::SparseMatrix<double> ref(n + 2, n);  // more rows than columns: the key is column-major
    ref.setFromTriplets(t.begin(), t.end());
    for (int threads : {1, 2, 5}) {
      omp_set_num_threads(threads);
      Eigen::SparseMatrix<double> m;
      numerics::triplets_to_matrix(t, n + 2, n, m);
      expect_identical(m, ref);
    }
  }
  omp_set_num_threads(saved);
  // Nothing, and empty columns at both ends.
  Eigen::SparseMatrix<double> m;
  numerics::triplets_to_matrix({}, 6, 6, m);
  EXPECT_EQ(m.nonZeros(), 0);
  EXPECT_EQ(m.outerIndexPtr()[6], 0);
  numerics::triplets_to_matrix({{2, 3, 1.5}, {2, 3, 2.0}, {0, 3, 1.0}}, 6, 6, m);
  ASSERT_EQ(m.nonZeros(), 2);
  EXPECT_EQ(m.coeff(2, 3), 3.5);
  EXPECT_EQ(m.outerIndexPtr()[3], 0);
  EXPECT_EQ(m.outerIndexPtr()[4], 2);
  EXPECT_EQ(m.outerIndexPtr()[6], 2);
}
