// Micro-benchmarks of the CPU kernels: points per second of the jet forward pass (value and
// all derivatives to third order) and of forward+backward, for d = 1 and 2 and batch sizes 4
// to 65536, on one thread; plus the fused loss step of one training batch (on the general kernel
// and on the epochs' fused kernel, cpu/epoch_kernel.hpp), and the machine's
// single-core FP32 peak measured by a register-only FMA loop, so the kernels' rate can be read
// as a fraction of it. FLOP counts per point are derived in docs/training.md and computed
// here by jet_flops().
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "core/jet_layout.hpp"
#include "core/offdomain.hpp"
#include "cpu/epoch_kernel.hpp"
#include "cpu/loss_step.hpp"
#include "cpu/mlp_jet.hpp"

using namespace yarnhom;

namespace {

// Floating-point operations per point: matrix products count 2 per multiply-add; the sigmoid
// jet map and its reverse count their arithmetic (exp as 1).
double jet_flops(const NetworkDesc& desc, int order, bool backward) {
  const int d = desc.input_dim, C = jet_channels(d, order);
  double f = 0;
  for (int k = 0; k < desc.num_layers(); ++k) {
    const double n = desc.layer_out(k), m = desc.layer_in(k);
    f += k == 0 ? 2 * n * m : 2 * n * m * C;  // forward: only the value channel in layer 0
    if (backward) f += 2 * n * m * C + (k > 0 ? 2 * n * m * C : 0);  // dW and Abar
  }
  // Sigmoid jet per hidden neuron: value 4, order 1: d, order 2: 4 per pair, order 3: 14 per
  // triple, s_n: 8; reverse about twice that.
  const double per = 12 + d + (order >= 2 ? 4 * jet_num_pairs(d) : 0) + (order >= 3 ? 14 * jet_num_triples(d) : 0);
  int hidden = 0;
  for (int h : desc.hidden) hidden += h;
  f += hidden * per * (backward ? 3 : 1);
  return f;
}

struct Inputs {
  NetworkDesc desc;
  std::vector<float> params, x, out, dout, grad;
};

Inputs make_inputs(int d, int batch, int order, std::vector<int> hidden = {16, 32, 16}) {
  Inputs in;
  in.desc.input_dim = d;
  in.desc.hidden = std::move(hidden);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1, 1);
  in.params.resize(in.desc.num_params());
  for (auto& p : in.params) p = u(rng) * 0.5f;
  in.x.resize(size_t(batch) * d);
  for (auto& v : in.x) v = u(rng);
  const int C = jet_channels(d, order);
  in.out.resize(size_t(C) * batch);
  in.dout.resize(size_t(C) * batch);
  for (auto& v : in.dout) v = u(rng);
  in.grad.resize(in.params.size());
  return in;
}

// Points per second and GFLOP/s of a forward (or forward and backward) pass over `batch` points.
void rate_counters(benchmark::State& st, const NetworkDesc& desc, int batch, int order, bool backward) {
  st.counters["points/s"] = benchmark::Counter(double(batch) * st.iterations(), benchmark::Counter::kIsRate);
  st.counters["GFLOP/s"] = benchmark::Counter(jet_flops(desc, order, backward) * batch * st.iterations() * 1e-9,
                                              benchmark::Counter::kIsRate);
}

// The jet forward pass over range(1) points of dimension range(0) at order 3, and with
// `backward` the reverse pass after it.
void jet_passes(benchmark::State& st, bool backward) {
  const int d = st.range(0), batch = st.range(1), order = 3;
  Inputs in = make_inputs(d, batch, order);
  cpu::JetWorkspace<float> ws;
  for (auto _ : st) {
    cpu::mlp_jet_forward<float>(in.desc, in.params.data(), in.x.data(), batch, order, in.out.data(), ws);
    if (backward) {
      std::fill(in.grad.begin(), in.grad.end(), 0.f);
      cpu::mlp_jet_backward<float>(in.desc, in.params.data(), in.x.data(), batch, order, in.dout.data(),
                                   in.grad.data(), ws);
    }
    benchmark::DoNotOptimize(in.out.data());
    benchmark::DoNotOptimize(in.grad.data());
  }
  rate_counters(st, in.desc, batch, order, backward);
}

void BM_jet_forward(benchmark::State& st) { jet_passes(st, false); }
void BM_jet_forward_backward(benchmark::State& st) { jet_passes(st, true); }

// One training step's loss and gradient as train-all runs it: a batch of data points (4 in
// 1D, 128 in 2D) at order 3 and 50 off-domain points at order 1. Arguments: d, the network
// (3: Net-3 [16, 32, 16], 2: Net-2 [32, 32]), the kernel (0: cpu::mlp_loss_grad, 1: the epochs'
// fused kernel cpu::fused_loss_grad, what the CPU backend runs).
void BM_training_step(benchmark::State& st) {
  const int d = st.range(0), m = d == 1 ? 4 : 128, k = 50;
  Inputs in = make_inputs(d, m, 3, st.range(1) == 3 ? std::vector<int>{16, 32, 16} : std::vector<int>{32, 32});
  std::vector<float> y(m, 0.1f), g(size_t(m) * d, 0.2f), xo(size_t(k) * d), no(size_t(k) * d);
  for (int j = 0; j < k; ++j) offdomain_point<float>(d, 7, j, &xo[j * d], &no[j * d]);
  cpu::LossBatch<float> b{m, in.x.data(), y.data(), g.data(), k, xo.data(), no.data()};
  cpu::LossWorkspace<float> ws;
  cpu::EpochWorkspace<float> fws;
  const bool fused = st.range(2) == 1;
  for (auto _ : st) {
    auto v = fused ? cpu::fused_loss_grad<float>(in.desc, in.params.data(), b, cpu::LossOptions{}, in.grad.data(), fws)
                   : cpu::mlp_loss_grad<float>(in.desc, in.params.data(), b, cpu::LossOptions{}, in.grad.data(), ws);
    benchmark::DoNotOptimize(v);
  }
  st.counters["steps/s"] = benchmark::Counter(double(st.iterations()), benchmark::Counter::kIsRate);
}

// The fused kernel as training uses it (cpu/loss_step.hpp): jets to third order, L_Z, L_F,
// L_C, backward, in chunks of 64 points that stay in cache, for any batch size.
void BM_fused_loss_grad(benchmark::State& st) {
  const int d = st.range(0), m = st.range(1);
  Inputs in = make_inputs(d, m, 3);
  std::vector<float> y(m, 0.1f), g(size_t(m) * d, 0.2f);
  cpu::LossBatch<float> b{m, in.x.data(), y.data(), g.data(), 0, nullptr, nullptr};
  cpu::LossWorkspace<float> ws;
  for (auto _ : st) {
    auto v = cpu::mlp_loss_grad<float>(in.desc, in.params.data(), b, cpu::LossOptions{}, in.grad.data(), ws);
    benchmark::DoNotOptimize(v);
  }
  st.counters["points/s"] = benchmark::Counter(double(m) * st.iterations(), benchmark::Counter::kIsRate);
  st.counters["GFLOP/s"] = benchmark::Counter(jet_flops(in.desc, 3, true) * m * st.iterations() * 1e-9,
                                              benchmark::Counter::kIsRate);
}

// Single-core FP32 peak: 12 independent chains of 16-wide FMAs, kept in registers.
void BM_fp32_peak(benchmark::State& st) {
  typedef float v16 __attribute__((vector_size(64)));
  v16 acc[12];
  for (int i = 0; i < 12; ++i) acc[i] = v16{} + float(i) * 1e-3f;
  const v16 a = v16{} + 0.999f, b = v16{} + 1e-4f;
  const long iters = 1 << 16;
  for (auto _ : st) {
    for (long i = 0; i < iters; ++i)
      for (int j = 0; j < 12; ++j) acc[j] = acc[j] * a + b;
    benchmark::DoNotOptimize(acc);
  }
  st.counters["GFLOP/s"] = benchmark::Counter(2.0 * 16 * 12 * iters * st.iterations() * 1e-9, benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_fp32_peak);
BENCHMARK(BM_jet_forward)->ArgsProduct({{1, 2}, {4, 64, 1024, 16384, 65536}});
BENCHMARK(BM_jet_forward_backward)->ArgsProduct({{1, 2}, {4, 64, 1024, 16384, 65536}});
BENCHMARK(BM_fused_loss_grad)->ArgsProduct({{1, 2}, {4, 64, 1024, 16384, 65536}});
BENCHMARK(BM_training_step)->ArgsProduct({{1, 2}, {3, 2}, {0, 1}});
BENCHMARK_MAIN();
