// The CPU backend's vectorized Adam step (cpu/adam_simd.hpp) against cpu::adam_update<float>
// (PyTorch's semantics, tests/train/test_optim.cpp): the same bits of weights and moments over
// 50 steps, for sizes below, at and past a multiple of the vector width.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "cpu/adam_simd.hpp"

using namespace yarnhom;

TEST(AdamSimd, SameBitsAsTheScalarStep) {
  std::mt19937 rng(1);
  std::normal_distribution<float> u(0, 1);
  for (int n : {1, 15, 16, 37, 1153}) {
    std::vector<float> p(n), g(n), m(n, 0.f), v(n, 0.f);
    for (float& x : p) x = u(rng);
    std::vector<float> p2 = p, m2 = m, v2 = v;
    cpu::AdamParams a;
    a.lr = 3e-3;
    for (int s = 1; s <= 50; ++s) {
      for (float& x : g) x = u(rng) * (s % 2 ? 1e-2f : 1e-5f);
      cpu::adam_update<float>(p.data(), g.data(), m.data(), v.data(), n, a, s);
      cpu::adam_update_simd(p2.data(), g.data(), m2.data(), v2.data(), n, a, s);
    }
    EXPECT_EQ(p2, p) << "n=" << n;
    EXPECT_EQ(m2, m) << "n=" << n;
    EXPECT_EQ(v2, v) << "n=" << n;
    EXPECT_NE(p2[0], 0.f);
  }
}
