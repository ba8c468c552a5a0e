// Every CUDA kernel against its CPU twin (cuda/api.hpp vs cpu/), on random weights and inputs,
// d = 1 and 2, float: relative error (the norm of the difference over the norm of the CPU's,
// per jet channel or per layer) under 1e-5 for values and input derivatives, 1e-4 for
// parameter gradients. Skipped, with a message, where no GPU is present.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <algorithm>
#include <random>

#include "cpu/adam.hpp"
#include "cpu/loss_step.hpp"
#include "cpu/losses.hpp"
#include "cpu/mlp_jet.hpp"
#include "cuda/api.hpp"
#include "tests/common/random_net.hpp"

using namespace yarnhom;

#define REQUIRE_GPU()                                                                    \
  if (cuda::device_count() == 0) GTEST_SKIP() << "no CUDA GPU here (" << cuda::device_description() << ")"

namespace {

std::vector<float> uniform(size_t n, float lo, float hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> v(n);
  for (auto& x : v) x = u(rng);
  return v;
}

double rel_err(const float* a, const float* b, size_t n) {
  double num = 0, den = 0;
  for (size_t i = 0; i < n; ++i) {
    num += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
    den += double(b[i]) * b[i];
  }
  return den > 0 ? std::sqrt(num / den) : std::sqrt(num);
}

// The parameter: 1 and 2 are Net-3 [16,32,16] in 1D and 2D; 3 is the default recipe's 2D
// network, Net-2 [32,32] (train/recipe.cpp).
int dim_of(int code) { return code == 1 ? 1 : 2; }

NetworkDesc net(int code) {
  NetworkDesc n;
  n.input_dim = dim_of(code);
  if (code == 3) n.hidden = {32, 32};
  return n;
}

}  // namespace

class CudaKernels : public ::testing::TestWithParam<int> {};

TEST_P(CudaKernels, ForwardJetMatchesCpu) {
  REQUIRE_GPU();
  const int d = dim_of(GetParam());
  const NetworkDesc desc = net(GetParam());
  for (int order = 0; order <= 3; ++order)
    for (int B : {1, 7, 300, 5000}) {
      const auto p = test::random_params<float>(desc, 11 + B + order);
      const auto x = uniform(size_t(B) * d, -1.5f, 1.5f, 3 + B);
      const int C = jet_channels(d, order);
      std::vector<float> ref(size_t(C) * B);
      cpu::JetWorkspace<float> cws;
      cpu::mlp_jet_forward<float>(desc, p.data(), x.data(), B, order, ref.data(), cws);
      cuda::DeviceVec<float> dp(p), dx(x), dout(ref.size());
      cuda::JetWorkspace ws;
      cuda::mlp_jet_forward(desc, dp.data(), dx.data(), B, order, dout.data(), ws);
      const auto out = dout.download();
      for (int c = 0; c < C; ++c)
        EXPECT_LT(rel_err(&out[size_t(c) * B], &ref[size_t(c) * B], B), 1e-5)
            << "d=" << d << " order=" << order << " B=" << B << " channel " << c;
    }
}

TEST_P(CudaKernels, BackwardMatchesCpu) {
  REQUIRE_GPU();
  const int d = dim_of(GetParam());
  const NetworkDesc desc = net(GetParam());
  for (int order = 0; order <= 3; ++order)
    for (int B : {1, 9, 260, 4000}) {
      const auto p = test::random_params<float>(desc, 5 + B + order);
      const auto x = uniform(size_t(B) * d, -1.5f, 1.5f, 7 + B);
      const int C = jet_channels(d, order);
      const auto dout = uniform(size_t(C) * B, -1.f, 1.f, 9 + B);
      std::vector<float> ref(p.size(), 0.f), out_cpu(size_t(C) * B);
      cpu::JetWorkspace<float> cws;
      cpu::mlp_jet_forward<float>(desc, p.data(), x.data(), B, order, out_cpu.data(), cws);
      cpu::mlp_jet_backward<float>(desc, p.data(), x.data(), B, order, dout.data(), ref.data(), cws);
      // The twin adds into dparams: start from a known non-zero vector.
      const auto base = uniform(p.size(), -1.f, 1.f, 1);
      cuda::DeviceVec<float> dp(p), dx(x), ddout(dout), dg(base);
      cuda::JetWorkspace ws;
      cuda::mlp_jet_backward(desc, dp.data(), dx.data(), B, order, ddout.data(), dg.data(), ws);
      auto g = dg.download();
      for (size_t i = 0; i < g.size(); ++i) g[i] -= base[i];
      for (int k = 0; k < desc.num_layers(); ++k) {
        const int off = desc.weight_offset(k), n = desc.weight_offset(k + 1) - off;
        EXPECT_LT(rel_err(&g[off], &ref[off], n), 1e-4) << "d=" << d << " order=" << order << " B=" << B << " layer " << k;
      }
    }
}

TEST_P(CudaKernels, DataAndStrainLossesMatchCpu) {
  REQUIRE_GPU();
  const int d = dim_of(GetParam());
  const int B = 777, C = jet_channels(d, 3), C1 = jet_channels(d, 1);
  LossWeights w;
  w.x = 0.5;  // exercise L_X too
  const auto jet = uniform(size_t(C) * B, -2.f, 2.f, 21);
  const auto y = uniform(B, -1.f, 1.f, 22), g = uniform(size_t(B) * d, -1.f, 1.f, 23);
  const auto wt = uniform(B, 0.f, 3.f, 24);  // per-point weights (the polish's relative fit)
  const float scale = 1.f / B;
  for (const bool weighted : {false, true}) {
    const float* wh = weighted ? wt.data() : nullptr;
    std::vector<float> djet_ref(jet.size(), 0.f);
    auto ref = cpu::data_losses<float>(d, B, 3, jet.data(), y.data(), g.data(), wh, w, true, scale, djet_ref.data());
    cuda::DeviceVec<float> djet_d(jet.size()), jet_d(jet), y_d(y), g_d(g), wt_d(wt);
    djet_d.fill_zero();
    auto got = cuda::data_losses(d, B, 3, jet_d.data(), y_d.data(), g_d.data(), weighted ? wt_d.data() : nullptr, w,
                                 true, scale, djet_d.data());
    EXPECT_NEAR(got.z, ref.z, 1e-5 * std::abs(ref.z)) << "weighted " << weighted;
    EXPECT_NEAR(got.f, ref.f, 1e-5 * std::abs(ref.f)) << "weighted " << weighted;
    EXPECT_NEAR(got.c, ref.c, 1e-5 * std::abs(ref.c));
    EXPECT_NEAR(got.x, ref.x, 1e-5 * std::abs(ref.x) + 1e-12);
    const auto djet = djet_d.download();
    EXPECT_LT(rel_err(djet.data(), djet_ref.data(), djet.size()), 1e-5) << "weighted " << weighted;
  }

  const int K = 333;
  const auto ojet = uniform(size_t(C1) * K, -2.f, 2.f, 31), nrm = uniform(size_t(K) * d, -1.f, 1.f, 32);
  std::vector<float> odj_ref(ojet.size(), 0.f);
  const float sref = cpu::strain_concentration_loss<float>(d, K, 1, ojet.data(), nrm.data(), 100.f / K, odj_ref.data());
  cuda::DeviceVec<float> ojet_d(ojet), nrm_d(nrm), odj_d(ojet.size());
  odj_d.fill_zero();
  const float sgot = cuda::strain_concentration_loss(d, K, 1, ojet_d.data(), nrm_d.data(), 100.f / K, odj_d.data());
  EXPECT_NEAR(sgot, sref, 1e-5 * std::abs(sref));
  const auto odj = odj_d.download();
  EXPECT_LT(rel_err(odj.data(), odj_ref.data(), odj.size()), 1e-5);
}

TEST_P(CudaKernels, FusedLossGradMatchesCpu) {
  REQUIRE_GPU();
  const int d = dim_of(GetParam());
  const NetworkDesc desc = net(GetParam());
  for (int m : {4, 128, 3000}) {
    const int K = 50;
    const auto p = test::random_params<float>(desc, 40 + m);
    const auto x = uniform(size_t(m) * d, -1.f, 1.f, 41), y = uniform(m, -1.f, 1.f, 42),
               g = uniform(size_t(m) * d, -1.f, 1.f, 43), xo = uniform(size_t(K) * d, -1.5f, 1.5f, 44),
               no = uniform(size_t(K) * d, -1.f, 1.f, 45);
    cpu::LossOptions opt;
    opt.w.x = 0.1;
    cpu::LossWorkspace<float> cws;
    std::vector<float> ref(p.size());
    cpu::LossBatch<float> hb{m, x.data(), y.data(), g.data(), K, xo.data(), no.data()};
    const cpu::LossValues rv = cpu::mlp_loss_grad<float>(desc, p.data(), hb, opt, ref.data(), cws);
    cuda::DeviceVec<float> dp(p), dx(x), dy(y), dg(g), dxo(xo), dno(no), dgrad(p.size());
    cuda::JetWorkspace ws;
    cpu::LossBatch<float> db{m, dx.data(), dy.data(), dg.data(), K, dxo.data(), dno.data()};
    const cpu::LossValues gv = cuda::mlp_loss_grad(desc, dp.data(), db, opt, dgrad.data(), ws);
    EXPECT_NEAR(gv.total, rv.total, 1e-5 * rv.total) << "m=" << m;
    EXPECT_NEAR(gv.z, rv.z, 1e-5 * rv.z);
    EXPECT_NEAR(gv.f, rv.f, 1e-5 * rv.f);
    EXPECT_NEAR(gv.c, rv.c, 1e-5 * rv.c);
    EXPECT_NEAR(gv.s, rv.s, 1e-5 * rv.s + 1e-12);
    const auto gg = dgrad.download();
    for (int k = 0; k < desc.num_layers(); ++k) {
      const int off = desc.weight_offset(k), n = desc.weight_offset(k + 1) - off;
      EXPECT_LT(rel_err(&gg[off], &ref[off], n), 1e-4) << "d=" << d << " m=" << m << " layer " << k;
    }
    // Deterministic: a second call gives the same bits.
    cuda::DeviceVec<float> dgrad2(p.size());
    cuda::mlp_loss_grad(desc, dp.data(), db, opt, dgrad2.data(), ws);
    const auto gg2 = dgrad2.download();
    EXPECT_EQ(0, std::memcmp(gg.data(), gg2.data(), gg.size() * sizeof(float)));
  }
}

// The fused loss + gradient at every data-jet order (L_C on: 3; off, L_X on: 2; both off: 1),
// on both code paths (the tensor-core warp path, the default for Net-3, and the block path),
// on a batch large enough that every warp of every block takes several tiles.
TEST_P(CudaKernels, FusedLossGradOrdersAndPathsMatchCpu) {
  REQUIRE_GPU();
  const int d = dim_of(GetParam());
  const NetworkDesc desc = net(GetParam());
  const int m = 40000 + 3, K = 1001;
  const auto p = test::random_params<float>(desc, 77);
  const auto x = uniform(size_t(m) * d, -1.f, 1.f, 71), y = uniform(m, -1.f, 1.f, 72),
             g = uniform(size_t(m) * d, -1.f, 1.f, 73), xo = uniform(size_t(K) * d, -1.5f, 1.5f, 74),
             no = uniform(size_t(K) * d, -1.f, 1.f, 75);
  cuda::DeviceVec<float> dp(p), dx(x), dy(y), dg(g), dxo(xo), dno(no), dgrad(p.size());
  cpu::LossBatch<float> hb{m, x.data(), y.data(), g.data(), K, xo.data(), no.data()};
  cpu::LossBatch<float> db{m, dx.data(), dy.data(), dg.data(), K, dxo.data(), dno.data()};
  for (int order : {3, 2, 1}) {
    cpu::LossOptions opt;
    opt.w.x = order == 1 ? 0.0 : 0.1;
    if (order < 3) opt.w.c = 0;
    ASSERT_EQ(cpu::data_jet_order(opt), order);
    cpu::LossWorkspace<float> cws;
    std::vector<float> ref(p.size());
    const cpu::LossValues rv = cpu::mlp_loss_grad<float>(desc, p.data(), hb, opt, ref.data(), cws);
    for (bool block_path : {false, true}) {
      cuda::LaunchShape shape;
      shape.block_path = block_path;
      cuda::set_launch_shape(shape);
      cuda::JetWorkspace ws;
      const cpu::LossValues gv = cuda::mlp_loss_grad(desc, dp.data(), db, opt, dgrad.data(), ws);
      cuda::set_launch_shape({});
      const std::string what = "d=" + std::to_string(d) + " order=" + std::to_string(order) +
                               (block_path ? " block path" : " tensor-core path");
      EXPECT_NEAR(gv.total, rv.total, 1e-5 * rv.total) << what;
      EXPECT_NEAR(gv.z, rv.z, 1e-5 * rv.z) << what;
      EXPECT_NEAR(gv.f, rv.f, 1e-5 * rv.f) << what;
      EXPECT_NEAR(gv.c, rv.c, 1e-5 * rv.c + 1e-12) << what;
      EXPECT_NEAR(gv.x, rv.x, 1e-5 * rv.x + 1e-12) << what;
      EXPECT_NEAR(gv.s, rv.s, 1e-5 * rv.s + 1e-12) << what;
      const auto gg = dgrad.download();
      double worst = 0;
      for (int k = 0; k < desc.num_layers(); ++k) {
        const int off = desc.weight_offset(k), n = desc.weight_offset(k + 1) - off;
        const double e = rel_err(&gg[off], &ref[off], n);
        worst = std::max(worst, e);
        EXPECT_LT(e, 1e-4) << what << " layer " << k;
      }
      std::printf("  %s: loss rel %.1e, worst layer gradient rel %.1e\n", what.c_str(),
                  std::abs(gv.total - rv.total) / rv.total, worst);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Dims, CudaKernels, ::testing::Values(1, 2, 3), [](const auto& i) {
  return i.param == 3 ? std::string("d2_net2") : "d" + std::to_string(i.param);
});

// The fragment layout of mma.sync m16n8k8 TF32 that cuda/mma_jet.cuh relies on (A: a0 =
// (g, t), a1 = (g + 8, t), a2 = (g, t + 4), a3 = (g + 8, t + 4); B: b0 = (k = t, n = g),
// b1 = (t + 4, g); C: c0, c1 = (g, 2t), (g, 2t + 1); c2, c3 = rows g + 8), g = lane / 4,
// t = lane % 4: small integers (exact in TF32) give the exact product; random floats through
// the 3xTF32 split agree with the double product to float accuracy, one TF32 MMA only to ~1e-3.
TEST(CudaMma, FragmentLayoutAnd3xTf32) {
  REQUIRE_GPU();
  std::vector<float> a(128), b(64);
  for (int i = 0; i < 128; ++i) a[i] = float((i * 7) % 23 - 11);
  for (int i = 0; i < 64; ++i) b[i] = float((i * 5) % 17 - 8);
  auto ref = [&](const std::vector<float>& A, const std::vector<float>& B) {
    std::vector<double> r(128, 0.0);
    for (int m = 0; m < 16; ++m)
      for (int n = 0; n < 8; ++n)
        for (int k = 0; k < 8; ++k) r[m * 8 + n] += double(A[m * 8 + k]) * B[k * 8 + n];
    return r;
  };
  const auto exact = ref(a, b);
  for (bool three : {false, true}) {
    const auto got = cuda::mma_tf32_probe(a, b, three);
    for (int i = 0; i < 128; ++i) EXPECT_EQ(double(got[i]), exact[i]) << "element " << i << (three ? " 3xTF32" : "");
  }
  a = uniform(128, -1.f, 1.f, 81);
  b = uniform(64, -1.f, 1.f, 82);
  const auto r = ref(a, b);
  double e1 = 0, e3 = 0, scale = 0;
  const auto g1 = cuda::mma_tf32_probe(a, b, false), g3 = cuda::mma_tf32_probe(a, b, true);
  for (int i = 0; i < 128; ++i) {
    e1 = std::max(e1, std::abs(g1[i] - r[i]));
    e3 = std::max(e3, std::abs(g3[i] - r[i]));
    scale = std::max(scale, std::abs(r[i]));
  }
  std::printf("  max error over max |D|: 1xTF32 %.1e, 3xTF32 %.1e\n", e1 / scale, e3 / scale);
  EXPECT_LT(e3 / scale, 1e-6);
  EXPECT_GT(e1 / scale, 1e-5);  // the split matters
}

TEST(CudaAdam, MatchesCpu) {
  REQUIRE_GPU();
  const int n = 1137;
  auto p = uniform(n, -1.f, 1.f, 51), m = uniform(n, -0.1f, 0.1f, 52), v = uniform(n, 0.f, 0.01f, 53);
  cuda::DeviceVec<float> dp(p), dm(m), dv(v);
  cpu::AdamParams a;
  a.lr = 3e-3;
  for (int64_t step = 1; step <= 20; ++step) {
    const auto g = uniform(n, -1.f, 1.f, 60 + unsigned(step));
    cpu::adam_update<float>(p.data(), g.data(), m.data(), v.data(), n, a, step);
    cuda::DeviceVec<float> dg(g);
    cuda::adam_update(dp.data(), dg.data(), dm.data(), dv.data(), n, a, step);
  }
  const auto gp = dp.download(), gm = dm.download(), gv = dv.download();
  EXPECT_LT(rel_err(gp.data(), p.data(), n), 1e-6);
  EXPECT_LT(rel_err(gm.data(), m.data(), n), 1e-6);
  EXPECT_LT(rel_err(gv.data(), v.data(), n), 1e-6);
  // The device Adam is written without FMA contraction; the CPU's is compiled by GCC, whose
  // C++ default (-ffp-contract=fast) may contract it, so the two need not agree bit for bit.
  int differ = 0;
  for (int i = 0; i < n; ++i) differ += gp[i] != p[i];
  std::printf("  Adam: %d of %d parameters differ from the CPU's after 20 steps\n", differ, n);
}
