// The epochs' fused kernel (cpu/epoch_kernel.hpp) against the general kernel (cpu::mlp_loss_grad)
// on the same minibatches (data points at jet order 3 with the exact L_C, or order 1 without it,
// plus off-domain points for L_S), entry by entry; its gradient against central finite
// differences in double; reruns bit-identical; satisfied off-domain points add nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cpu/epoch_kernel.hpp"
#include "cpu/loss_step.hpp"
#include "tests/common/random_net.hpp"

using namespace yarnhom;

namespace {

template <class T>
struct Batch {
  std::vector<T> x, y, g, wt, xo, no;
  cpu::LossBatch<T> batch(bool weighted) const {
    return {int(y.size()), x.data(), y.data(), g.data(), int(xo.size()) / d, xo.data(), no.data(),
            weighted ? wt.data() : nullptr};
  }
  int d = 1;
};

// m data points in [-1, 1]^d and k off-domain points with unit normals in random directions
// (about half of them see a decreasing energy along the normal: L_S is active there).
template <class T>
Batch<T> make_batch(int d, int m, int k, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Batch<T> b;
  b.d = d;
  for (int i = 0; i < m * d; ++i) b.x.push_back(T(u(rng))), b.g.push_back(T(2 * u(rng)));
  for (int i = 0; i < m; ++i) b.y.push_back(T(u(rng))), b.wt.push_back(T(1.5 + u(rng)));
  // In pairs: the same point with opposite normals, so that one of each pair is active.
  for (int i = 0; i < k; ++i) {
    if (i % 2 == 1) {
      for (int j = 0; j < d; ++j) b.xo.push_back(b.xo[b.xo.size() - d]), b.no.push_back(-b.no[b.no.size() - d]);
      continue;
    }
    double n[2] = {u(rng), d == 2 ? u(rng) : 0.0};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1]) + 1e-3, r = 1.05 + 0.3 * std::abs(u(rng));
    for (int j = 0; j < d; ++j) {
      b.no.push_back(T(n[j] / len));
      b.xo.push_back(T(r * n[j] / len));
    }
  }
  return b;
}

NetworkDesc net(int d, std::vector<int> hidden) {
  NetworkDesc n;
  n.input_dim = d;
  n.hidden = std::move(hidden);
  return n;
}

// The paper's weights (L_C exact at order 3), or without L_C (order 1).
cpu::LossOptions options(bool with_c) {
  cpu::LossOptions o;
  o.w = LossWeights{1.0, 0.05, with_c ? 1e-3 : 0.0, 1e2, 0.0};
  return o;
}

// Every entry of the fused gradient g within tol of the reference r computed in double on the
// same (rounded) inputs: |g - r| <= tol |r| + floor, the floor being the larger of tol x 1e-4
// x max |r| (entries that are rounding noise of a sum with cancellation) and twice the largest
// error of the general kernel run in T (in float its own rounding; zero in double).
template <class T>
void expect_entries_close(const std::vector<T>& g, const std::vector<double>& r, const std::vector<T>& general,
                          double tol, const std::string& what) {
  double big = 0, general_err = 0;
  for (size_t i = 0; i < r.size(); ++i) {
    big = std::max(big, std::abs(r[i]));
    general_err = std::max(general_err, std::abs(double(general[i]) - r[i]));
  }
  const double floor = std::max(tol * 1e-4 * big, 2 * general_err);
  int bad = 0;
  for (size_t i = 0; i < g.size(); ++i)
    if (std::abs(double(g[i]) - r[i]) > tol * std::abs(r[i]) + floor && ++bad <= 5)
      ADD_FAILURE() << what << " entry " << i << ": " << g[i] << " vs " << r[i];
  EXPECT_EQ(bad, 0) << what;
}

template <class T>
void compare(const NetworkDesc& desc, bool with_c, int m, int k, bool weighted, double tol) {
  const cpu::LossOptions o = options(with_c);
  ASSERT_TRUE(cpu::fused_loss_supported(desc, o));
  const std::vector<T> p = test::random_params<T>(desc, 7 + m + k);
  const Batch<T> pts = make_batch<T>(desc.input_dim, m, k, 11 + m + k);
  const cpu::LossBatch<T> b = pts.batch(weighted);
  cpu::LossWorkspace<T> ws;
  cpu::EpochWorkspace<T> fws;
  std::vector<T> g_gen(p.size()), g(p.size(), T(123));
  cpu::mlp_loss_grad<T>(desc, p.data(), b, o, g_gen.data(), ws, 1);
  const cpu::LossValues v = cpu::fused_loss_grad<T>(desc, p.data(), b, o, g.data(), fws);
  // The reference: the general kernel in double on the same inputs.
  auto wide = [](const std::vector<T>& a) { return std::vector<double>(a.begin(), a.end()); };
  Batch<double> pd{wide(pts.x), wide(pts.y), wide(pts.g), wide(pts.wt), wide(pts.xo), wide(pts.no)};
  pd.d = pts.d;
  const std::vector<double> p_d = wide(p);
  cpu::LossWorkspace<double> ws_d;
  std::vector<double> g_ref(p.size());
  const cpu::LossValues ref = cpu::mlp_loss_grad<double>(desc, p_d.data(), pd.batch(weighted), o, g_ref.data(), ws_d, 1);
  const std::string what = "d=" + std::to_string(desc.input_dim) + " layers " + std::to_string(desc.hidden.size()) +
                           " c=" + std::to_string(with_c) + " m=" + std::to_string(m) + " k=" + std::to_string(k);
  if (m > 0) {
    ASSERT_GT(ref.z, 1e-3) << what;
    ASSERT_GT(ref.f, 1e-3) << what;
    if (with_c) ASSERT_GT(ref.c, 1e-3) << what;
  }
  if (k > 0) ASSERT_GT(ref.s, 1e-7) << what;  // some off-domain points active
  EXPECT_NEAR(v.z, ref.z, tol * ref.z) << what;
  EXPECT_NEAR(v.f, ref.f, tol * ref.f) << what;
  EXPECT_NEAR(v.c, ref.c, tol * ref.c) << what;
  EXPECT_NEAR(v.s, ref.s, tol * ref.s) << what;
  EXPECT_NEAR(v.total, ref.total, tol * ref.total) << what;
  expect_entries_close(g, g_ref, g_gen, tol, what);
  // Without a gradient buffer: the same losses; the same inputs again: the same bits.
  const cpu::LossValues v2 = cpu::fused_loss_grad<T>(desc, p.data(), b, o, nullptr, fws);
  EXPECT_EQ(v2.total, v.total) << what;
  std::vector<T> g2(p.size());
  cpu::fused_loss_grad<T>(desc, p.data(), b, o, g2.data(), fws);
  EXPECT_EQ(g2, g) << what;
}

const std::vector<std::vector<int>> kShapes = {{16, 32, 16}, {32, 32}};

TEST(EpochKernel, MatchesTheGeneralKernelInDouble) {
  for (int d : {1, 2})
    for (const auto& h : kShapes)
      for (bool c : {true, false}) {
        compare<double>(net(d, h), c, 4, 50, false, 1e-12);    // the 1D terms' minibatch
        compare<double>(net(d, h), c, 128, 50, false, 1e-12);  // the 2D terms'
        compare<double>(net(d, h), c, 37, 0, true, 1e-12);     // weighted, no off-domain
        compare<double>(net(d, h), c, 0, 21, false, 1e-12);    // off-domain only
      }
}

TEST(EpochKernel, MatchesTheGeneralKernelInFloat) {
  for (int d : {1, 2})
    for (const auto& h : kShapes)
      for (bool c : {true, false}) {
        compare<float>(net(d, h), c, 4, 50, false, 2e-5);
        compare<float>(net(d, h), c, 128, 50, false, 2e-5);
        compare<float>(net(d, h), c, 87, 256, false, 2e-5);  // a validation batch
      }
}

TEST(EpochKernel, GradientMatchesFiniteDifferences) {
  for (int d : {1, 2})
    for (const auto& h : kShapes) {
      const NetworkDesc desc = net(d, h);
      const cpu::LossOptions o = options(true);
      std::vector<double> p = test::random_params<double>(desc, 3);
      const Batch<double> pts = make_batch<double>(d, 19, 23, 5);
      const cpu::LossBatch<double> b = pts.batch(false);
      cpu::EpochWorkspace<double> ws;
      std::vector<double> g(p.size());
      cpu::fused_loss_grad<double>(desc, p.data(), b, o, g.data(), ws);
      double num = 0, den = 0;
      const double step = 1e-6;
      for (size_t i = 0; i < p.size(); ++i) {
        const double keep = p[i];
        p[i] = keep + step;
        const double lp = cpu::fused_loss_grad<double>(desc, p.data(), b, o, nullptr, ws).total;
        p[i] = keep - step;
        const double lm = cpu::fused_loss_grad<double>(desc, p.data(), b, o, nullptr, ws).total;
        p[i] = keep;
        const double fd = (lp - lm) / (2 * step);
        num += (g[i] - fd) * (g[i] - fd);
        den += fd * fd;
      }
      EXPECT_LT(std::sqrt(num / den), 1e-6) << "d=" << d << " layers " << h.size();
    }
}

// Off-domain points that all satisfy L_S (their groups' reverse passes are skipped) add nothing:
// the gradient is the data points' alone, bit for bit; one active point among them (the last
// group) still matches the general kernel.
TEST(EpochKernel, SatisfiedOffDomainPointsAddNothingToTheGradient) {
  for (int d : {1, 2})
    for (const auto& h : kShapes) {
      const NetworkDesc desc = net(d, h);
      const cpu::LossOptions o = options(true);
      const std::vector<float> p = test::random_params<float>(desc, 9);
      const Batch<float> all = make_batch<float>(d, 128, 400, 13);
      cpu::EpochWorkspace<float> ws;
      // Keep the off-domain points whose own L_S is zero.
      Batch<float> sat = all, one = all;
      sat.xo.clear(), sat.no.clear();
      for (size_t i = 0; i * d < all.xo.size(); ++i) {
        one.xo.assign(all.xo.begin() + i * d, all.xo.begin() + (i + 1) * d);
        one.no.assign(all.no.begin() + i * d, all.no.begin() + (i + 1) * d);
        one.y.clear();
        if (cpu::fused_loss_grad<float>(desc, p.data(), one.batch(false), o, nullptr, ws).s == 0) {
          sat.xo.insert(sat.xo.end(), one.xo.begin(), one.xo.end());
          sat.no.insert(sat.no.end(), one.no.begin(), one.no.end());
        }
      }
      ASSERT_GE(sat.xo.size(), size_t(70 * d)) << "d=" << d;  // more than two groups of points
      Batch<float> data = all;
      data.xo.clear(), data.no.clear();
      std::vector<float> g_sat(p.size()), g_data(p.size());
      EXPECT_EQ(cpu::fused_loss_grad<float>(desc, p.data(), sat.batch(false), o, g_sat.data(), ws).s, 0.0);
      cpu::fused_loss_grad<float>(desc, p.data(), data.batch(false), o, g_data.data(), ws);
      EXPECT_EQ(g_sat, g_data) << "d=" << d << " layers " << h.size();
      // One active point appended (the partner of a satisfied one: the same point, the normal
      // reversed): the gradient changes, as the general kernel's does.
      Batch<float> mixed = sat;
      mixed.xo.insert(mixed.xo.end(), sat.xo.begin(), sat.xo.begin() + d);
      for (int j = 0; j < d; ++j) mixed.no.push_back(-sat.no[j]);
      cpu::LossWorkspace<float> gws;
      std::vector<float> g_mix(p.size()), g_gen(p.size());
      const cpu::LossValues v = cpu::fused_loss_grad<float>(desc, p.data(), mixed.batch(false), o, g_mix.data(), ws);
      cpu::mlp_loss_grad<float>(desc, p.data(), mixed.batch(false), o, g_gen.data(), gws, 1);
      ASSERT_GT(v.s, 0.0);
      EXPECT_NE(g_mix, g_data);
      double err = 0, big = 0;
      for (size_t i = 0; i < p.size(); ++i) {
        err = std::max(err, std::abs(double(g_mix[i]) - g_gen[i]));
        big = std::max(big, std::abs(double(g_gen[i])));
      }
      EXPECT_LT(err, 1e-4 * big) << "d=" << d << " layers " << h.size();
    }
}

TEST(EpochKernel, CoversOnlyTheCompiledShapesAndLosses) {
  EXPECT_TRUE(cpu::fused_loss_supported(net(1, {16, 32, 16}), options(true)));
  EXPECT_TRUE(cpu::fused_loss_supported(net(2, {32, 32}), options(false)));
  EXPECT_FALSE(cpu::fused_loss_supported(net(2, {32, 64, 32}), options(true)));
  cpu::LossOptions stencil = options(true);
  stencil.stencil_c = true;
  EXPECT_FALSE(cpu::fused_loss_supported(net(2, {32, 32}), stencil));
  cpu::LossOptions convex = options(true);
  convex.w.x = 1;
  EXPECT_FALSE(cpu::fused_loss_supported(net(2, {32, 32}), convex));
}

}  // namespace
