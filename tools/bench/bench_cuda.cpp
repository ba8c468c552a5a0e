// Kernel micro-benchmarks of the CUDA backend, CPU alongside: points per second of the fused
// forward jets (order 3) + losses (L_Z, L_F, exact L_C) + reverse pass + fixed-order gradient
// reduction of one network (cuda::mlp_loss_grad vs cpu::mlp_loss_grad), d = 1 and 2, batch 4 to
// 2^20. CUDA: timed with CUDA events around each call after warm-up; the reported time is the
// median of the iterations. CPU: wall clock, all cores. FLOPs per point count the matrix
// products only (docs/cuda.md); "of_peak" divides by the GPU's FP32 rate measured at start.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "core/jet_layout.hpp"
#include "cpu/loss_step.hpp"
#include "cuda/api.hpp"
#include "cuda/block_jacobi_pcg.hpp"
#include "numerics/block_jacobi_pcg.hpp"
#include "tests/common/pcg_test_system.hpp"

using namespace yarnhom;

namespace {

double g_peak = 0;  // FLOP/s

// Matrix-product FLOPs per point of the fused pass (an FMA = 2): layer 0's value; for every
// later layer the forward product, the weight gradient and the input adjoint, each
// 2 * out * in per jet channel; layer 0's weight gradient.
double flops_per_point(const NetworkDesc& desc, int order) {
  const int d = desc.input_dim, C = jet_channels(d, order);
  double f = 2.0 * d * desc.layer_out(0);
  for (int k = 1; k < desc.num_layers(); ++k) f += 3 * 2.0 * desc.layer_out(k) * desc.layer_in(k) * C;
  f += 2.0 * d * desc.layer_out(0);
  return f;
}

struct Problem {
  NetworkDesc desc;
  std::vector<float> p, x, y, g;
  explicit Problem(int d, int n) {
    desc.input_dim = d;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    p.resize(desc.num_params());
    for (auto& v : p) v = 0.5f * u(rng);
    x.resize(size_t(n) * d), y.resize(n), g.resize(size_t(n) * d);
    for (auto& v : x) v = u(rng);
    for (auto& v : y) v = u(rng);
    for (auto& v : g) v = u(rng);
  }
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void report(benchmark::State& state, const NetworkDesc& desc, int n, double sec) {
  const double fpp = flops_per_point(desc, 3);
  state.counters["median_us"] = sec * 1e6;
  state.counters["points_per_s"] = n / sec;
  state.counters["GFLOP_per_s"] = fpp * n / sec * 1e-9;
  if (g_peak > 0) state.counters["of_peak"] = fpp * n / sec / g_peak;
}

void BM_Cuda_FusedFwdBwd(benchmark::State& state) {
  const int d = int(state.range(0)), n = int(state.range(1));
  cuda::LaunchShape shape;
  shape.threads = int(state.range(2));
  shape.stride = int(state.range(3));
  shape.block_path = state.range(4) != 0;
  cuda::set_launch_shape(shape);
  Problem pr(d, n);
  cuda::DeviceVec<float> dp(pr.p), dx(pr.x), dy(pr.y), dg(pr.g), grad(pr.p.size());
  cuda::JetWorkspace ws;
  cpu::LossOptions opt;
  cpu::LossBatch<float> b{n, dx.data(), dy.data(), dg.data(), 0, nullptr, nullptr};
  try {
    for (int i = 0; i < 3; ++i) cuda::mlp_loss_grad_launch(pr.desc, dp.data(), b, opt, grad.data(), ws);
    cuda::synchronize();
  } catch (const cuda::CudaError& e) {
    cuda::set_launch_shape({});
    state.SkipWithError(e.what());
    return;
  }
  cuda::EventTimer t;
  std::vector<double> secs;
  for (auto _ : state) {
    t.start();
    cuda::mlp_loss_grad_launch(pr.desc, dp.data(), b, opt, grad.data(), ws);
    const double s = t.stop_ms() * 1e-3;
    secs.push_back(s);
    state.SetIterationTime(s);
  }
  cuda::set_launch_shape({});
  report(state, pr.desc, n, median(secs));
}

void BM_Cpu_FusedFwdBwd(benchmark::State& state) {
  const int d = int(state.range(0)), n = int(state.range(1));
  Problem pr(d, n);
  cpu::LossOptions opt;
  cpu::LossWorkspace<float> ws;
  std::vector<float> grad(pr.p.size());
  cpu::LossBatch<float> b{n, pr.x.data(), pr.y.data(), pr.g.data(), 0, nullptr, nullptr};
  const int threads = omp_get_max_threads();
  cpu::mlp_loss_grad<float>(pr.desc, pr.p.data(), b, opt, grad.data(), ws, threads);
  std::vector<double> secs;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    cpu::mlp_loss_grad<float>(pr.desc, pr.p.data(), b, opt, grad.data(), ws, threads);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    secs.push_back(s);
    state.SetIterationTime(s);
  }
  state.counters["threads"] = threads;
  report(state, pr.desc, n, median(secs));
}

// Batch 4 to 2^20 (the CPU to 2^18: its per-chunk workspaces for 2^20 points of d = 2 would
// take over 5 GB).
void sizes(benchmark::internal::Benchmark* b, bool cuda) {
  for (int d : {1, 2})
    for (int lg = 2; lg <= (cuda ? 20 : 18); lg += 2) {
      if (cuda)
        b->Args({d, 1 << lg, 0, 0, 0});
      else
        b->Args({d, 1 << lg});
    }
  b->UseManualTime()->MinTime(0.2)->Unit(benchmark::kMicrosecond);
}

}  // namespace

// Args: d, batch, threads per block (0: default), chunk stride (block path; 0: default),
// block path (1) or the tensor-core warp path (0, the default for Net-3).
BENCHMARK(BM_Cuda_FusedFwdBwd)->Apply([](auto* b) { sizes(b, true); });
// The block path (the kernel before the tensor-core path) at the largest batch, same process.
BENCHMARK(BM_Cuda_FusedFwdBwd)
    ->ArgsProduct({{1, 2}, {1 << 20}, {0}, {0}, {1}})
    ->UseManualTime()
    ->MinTime(0.2)
    ->Unit(benchmark::kMicrosecond)
    ->Name("BM_Cuda_BlockPath");
// Warps per block of the tensor-core path at the largest batch (capped by shared memory).
BENCHMARK(BM_Cuda_FusedFwdBwd)
    ->ArgsProduct({{1, 2}, {1 << 20}, {128, 256, 384, 512}, {0}, {0}})
    ->UseManualTime()
    ->MinTime(0.2)
    ->Unit(benchmark::kMicrosecond)
    ->Name("BM_Cuda_MmaWarps");
// Launch shapes of the block path at the largest batch: (threads per block, chunk stride).
BENCHMARK(BM_Cuda_FusedFwdBwd)
    ->ArgsProduct({{1, 2}, {1 << 20}, {128, 256, 512}, {68, 100, 196, 228}, {1}})
    ->UseManualTime()
    ->MinTime(0.2)
    ->Unit(benchmark::kMicrosecond)
    ->Name("BM_Cuda_LaunchShape");
BENCHMARK(BM_Cpu_FusedFwdBwd)->Apply([](auto* b) { sizes(b, false); });

// One solve of the block-Jacobi PCG's GPU twin (cuda/block_jacobi_pcg.cu: five launches an
// iteration in CUDA graphs of eight) to the one-solve step's relative residual 1e-3, on the
// shell's stencil (tests/common/pcg_test_system.hpp: range(0) vertices a side, 121: a T-shirt's
// 43,923 unknowns, 57 entries a row); the system uploaded once. The CPU twin's is
// BM_BlockJacobiPcg (bench_sim.cpp), on the same system.
void BM_CudaBlockJacobiPcg(benchmark::State& state) {
  const Eigen::SparseMatrix<double> L = test::pcg_shell_system(int(state.range(0)), 0.001, 1.0);
  numerics::BlockJacobiBuilder builder;
  numerics::BlockCsr A;
  builder.build(L, A);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.n, -1.0, 1.0).array().sin();
  Eigen::VectorXd x(A.n);
  auto dev = cuda::make_pcg_device();
  dev->upload(A);
  numerics::BlockPcgResult r;
  double seconds = 0;
  long iterations = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    r = dev->solve(b.data(), x.data(), 1e-3, 100000);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    iterations += r.iterations;
  }
  state.counters["unknowns"] = A.n;
  state.counters["iterations"] = r.iterations;
  state.counters["us_per_iteration"] = iterations > 0 ? 1e6 * seconds / double(iterations) : 0.0;
}
BENCHMARK(BM_CudaBlockJacobiPcg)->Arg(121)->Arg(90)->Unit(benchmark::kMillisecond)->UseRealTime();

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (cuda::device_count() == 0) {
    std::fprintf(stderr, "bench_cuda: %s; nothing to measure\n", cuda::device_description().c_str());
    return 0;
  }
  g_peak = cuda::measure_fp32_peak();
  std::printf("GPU: %s, measured FP32 peak %.1f TFLOP/s; FLOPs per point (order 3): d=1 %.0f, d=2 %.0f\n",
              cuda::device_description().c_str(), g_peak * 1e-12,
              flops_per_point([] { NetworkDesc n; n.input_dim = 1; return n; }(), 3),
              flops_per_point([] { NetworkDesc n; n.input_dim = 2; return n; }(), 3));
  benchmark::AddCustomContext("gpu", cuda::device_description());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
