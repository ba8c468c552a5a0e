// The polish's fused order-1 kernel (cpu/polish_kernel.hpp) against the epochs' general kernel
// (cpu::mlp_loss_grad at jet order 1) on the same points, and its gradient against central
// finite differences in double; point counts that do not fill the last group of lanes. 2D Net-2
// runs the double-backpropagation path, the other shapes the jets.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cpu/loss_step.hpp"
#include "cpu/polish_kernel.hpp"
#include "tests/common/random_net.hpp"

using namespace yarnhom;

namespace {

template <class T>
struct Points {
  std::vector<T> x, y, g, wt;
  cpu::LossBatch<T> batch(bool weighted) const {
    return {int(y.size()), x.data(), y.data(), g.data(), 0, nullptr, nullptr, weighted ? wt.data() : nullptr};
  }
};

template <class T>
Points<T> points(int d, int m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Points<T> p;
  for (int i = 0; i < m * d; ++i) p.x.push_back(T(u(rng))), p.g.push_back(T(2 * u(rng)));
  for (int i = 0; i < m; ++i) p.y.push_back(T(u(rng))), p.wt.push_back(T(1.5 + u(rng)));
  return p;
}

NetworkDesc net(int d, std::vector<int> hidden) {
  NetworkDesc n;
  n.input_dim = d;
  n.hidden = std::move(hidden);
  return n;
}

cpu::LossOptions data_only() {
  cpu::LossOptions o;
  o.w = LossWeights{1.0, 0.05, 0.0, 0.0, 0.0};
  return o;
}

template <class T>
void compare(const NetworkDesc& desc, int m, bool weighted, double tol) {
  ASSERT_TRUE(cpu::fused_order1_supported(desc));
  const std::vector<T> p = test::random_params<T>(desc, 7 + m);
  const Points<T> pts = points<T>(desc.input_dim, m, 11 + m);
  const cpu::LossBatch<T> b = pts.batch(weighted);
  const cpu::LossOptions o = data_only();
  cpu::LossWorkspace<T> ws;
  cpu::FusedWorkspace<T> fws;
  std::vector<T> g_ref(p.size()), g(p.size(), T(123));
  const cpu::LossValues ref = cpu::mlp_loss_grad<T>(desc, p.data(), b, o, g_ref.data(), ws, 1);
  const cpu::LossValues v = cpu::fused_data_loss_grad<T>(desc, p.data(), b, o.w, g.data(), fws);
  ASSERT_GT(ref.z, 1e-3);
  ASSERT_GT(ref.f, 1e-3);
  EXPECT_NEAR(v.z, ref.z, tol * ref.z) << "m=" << m;
  EXPECT_NEAR(v.f, ref.f, tol * ref.f) << "m=" << m;
  EXPECT_NEAR(v.total, ref.total, tol * ref.total) << "m=" << m;
  double num = 0, den = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    num += double(g[i] - g_ref[i]) * double(g[i] - g_ref[i]);
    den += double(g_ref[i]) * double(g_ref[i]);
  }
  EXPECT_LT(std::sqrt(num / den), tol) << "m=" << m;
  // Without a gradient buffer: the same losses; the same inputs again: the same bits.
  const cpu::LossValues v2 = cpu::fused_data_loss_grad<T>(desc, p.data(), b, o.w, nullptr, fws);
  EXPECT_EQ(v2.total, v.total);
  std::vector<T> g2(p.size());
  cpu::fused_data_loss_grad<T>(desc, p.data(), b, o.w, g2.data(), fws);
  EXPECT_EQ(g2, g);
}

TEST(PolishKernel, MatchesTheGeneralKernelInDouble) {
  for (int d : {1, 2})
    for (const auto& h : {std::vector<int>{16, 32, 16}, std::vector<int>{32, 32}})
      for (int m : {1, 5, 16, 37, 91})
        for (bool weighted : {false, true}) compare<double>(net(d, h), m, weighted, 1e-12);
}

TEST(PolishKernel, MatchesTheGeneralKernelInFloat) {
  for (int d : {1, 2})
    for (const auto& h : {std::vector<int>{16, 32, 16}, std::vector<int>{32, 32}})
      for (int m : {3, 64, 200}) compare<float>(net(d, h), m, true, 2e-5);
}

TEST(PolishKernel, GradientMatchesFiniteDifferences) {
  for (int d : {1, 2}) {
    const NetworkDesc desc = net(d, d == 1 ? std::vector<int>{16, 32, 16} : std::vector<int>{32, 32});
    std::vector<double> p = test::random_params<double>(desc, 3);
    const Points<double> pts = points<double>(d, 23, 5);
    const cpu::LossBatch<double> b = pts.batch(true);
    const LossWeights w{1.0, 0.05, 0.0, 0.0, 0.0};
    cpu::FusedWorkspace<double> ws;
    std::vector<double> g(p.size());
    cpu::fused_data_loss_grad<double>(desc, p.data(), b, w, g.data(), ws);
    double num = 0, den = 0;
    const double h = 1e-6;
    for (size_t i = 0; i < p.size(); ++i) {
      const double keep = p[i];
      p[i] = keep + h;
      const double lp = cpu::fused_data_loss_grad<double>(desc, p.data(), b, w, nullptr, ws).total;
      p[i] = keep - h;
      const double lm = cpu::fused_data_loss_grad<double>(desc, p.data(), b, w, nullptr, ws).total;
      p[i] = keep;
      const double fd = (lp - lm) / (2 * h);
      num += (g[i] - fd) * (g[i] - fd);
      den += fd * fd;
    }
    EXPECT_LT(std::sqrt(num / den), 1e-6) << "d=" << d;
  }
}

TEST(PolishKernel, CoversOnlyTheCompiledShapes) {
  EXPECT_TRUE(cpu::fused_order1_supported(net(1, {16, 32, 16})));
  EXPECT_TRUE(cpu::fused_order1_supported(net(2, {32, 32})));
  EXPECT_FALSE(cpu::fused_order1_supported(net(2, {32, 64, 32})));
  EXPECT_FALSE(cpu::fused_order1_supported(net(1, {8})));
}

}  // namespace
