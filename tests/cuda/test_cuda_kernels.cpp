// Every CUDA kernel against its CPU twin (cuda/api.hpp vs cpu/), on random weights and inputs,
// d = 1 and 2, float: relative error (the norm of the difference over the norm of the CPU's,
// per jet channel or per layer) under 1e-5 for values and input derivatives, 1e-4 for
// parameter gradients. Skipped, with a message, where no GPU is present.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
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

NetworkDesc net(int d) {
  NetworkDesc n;
  n.input_dim = d;
  return n;
}

}  // namespace

class CudaKernels : public ::testing::TestWithParam<int> {};

TEST_P(CudaKernels, ForwardJetMatchesCpu) {
  REQUIRE_GPU();
  const int d = GetParam();
  const NetworkDesc desc = net(d);
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
  const int d = GetParam();
  const NetworkDesc desc = net(d);
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
  const int d = GetParam();
  const int B = 777, C = jet_channels(d, 3), C1 = jet_channels(d, 1);
  LossWeights w;
  w.x = 0.5;  // exercise L_X too
  const auto jet = uniform(size_t(C) * B, -2.f, 2.f, 21);
  const auto y = uniform(B, -1.f, 1.f, 22), g = uniform(size_t(B) * d, -1.f, 1.f, 23);
  std::vector<float> djet_ref(jet.size(), 0.f);
  const float scale = 1.f / B;
  auto ref = cpu::data_losses<float>(d, B, 3, jet.data(), y.data(), g.data(), w, true, scale, djet_ref.data());
  cuda::DeviceVec<float> djet_d(jet.size()), jet_d(jet), y_d(y), g_d(g);
  djet_d.fill_zero();
  auto got = cuda::data_losses(d, B, 3, jet_d.data(), y_d.data(), g_d.data(), w, true, scale, djet_d.data());
  EXPECT_NEAR(got.z, ref.z, 1e-5 * std::abs(ref.z));
  EXPECT_NEAR(got.f, ref.f, 1e-5 * std::abs(ref.f));
  EXPECT_NEAR(got.c, ref.c, 1e-5 * std::abs(ref.c));
  EXPECT_NEAR(got.x, ref.x, 1e-5 * std::abs(ref.x) + 1e-12);
  const auto djet = djet_d.download();
  EXPECT_LT(rel_err(djet.data(), djet_ref.data(), djet.size()), 1e-5);

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
  const int d = GetParam();
  const NetworkDesc desc = net(d);
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

INSTANTIATE_TEST_SUITE_P(Dims, CudaKernels, ::testing::Values(1, 2), [](const auto& i) {
  return "d" + std::to_string(i.param);
});

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
