// Micro-benchmarks of the default recipe's L-BFGS polish, part by part (docs/benchmarks.md,
// "The polish"): the full-batch loss and gradient of one evaluation (cpu::mlp_loss_grad on the
// polish's problems: a 2D term, Net-2 [32, 32], 865 points in float, and a 1D term, Net-3
// [16, 32, 16], 91 points in double, the sizes of `synth --preset paper`), the 1D rest penalty
// (one second-order jet),
// the two-loop recursion, and whole polishes of a fixed number of iterations; with the CUDA
// backend also the GPU polish of 14 such networks in one launch (BM_CudaPolish).
//
// The data are a smooth analytic energy on the term's grid (y = sin(1.3 x) cos(0.7 y) + x y /2
// and its gradient), the weights PyTorch's default initialization: what is timed does not depend
// on how well the network fits.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <random>
#include <vector>

#include "cpu/loss_step.hpp"
#include "cpu/mlp_jet.hpp"
#include "cpu/polish_kernel.hpp"
#include "train/lbfgs.hpp"
#include "train/polish.hpp"
#ifdef YARNHOM_HAVE_CUDA
#include "cuda/api.hpp"
#include "train/cuda_polish.hpp"
#endif

using namespace yarnhom;

namespace {

// A term's problem: d = 1: 101 grid points, d = 2: 31 x 31; 10 % held out.
NetworkJob make_problem(int d, uint32_t seed = 1) {
  NetworkJob job;
  job.name = d == 1 ? "1d" : "2d";
  job.desc.input_dim = d;
  job.desc.hidden = d == 1 ? std::vector<int>{16, 32, 16} : std::vector<int>{32, 32};
  const int n1 = d == 1 ? 101 : 31, n = d == 1 ? n1 : n1 * n1;
  std::mt19937 rng(seed);
  std::vector<int> perm(n);
  for (int i = 0; i < n; ++i) perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), rng);
  const int n_val = int(std::lround(0.1 * n));
  for (int q = 0; q < n; ++q) {
    const int i = perm[q];
    const double a = -1 + 2.0 * (i % n1) / (n1 - 1), b = d == 2 ? -1 + 2.0 * (i / n1) / (n1 - 1) : 0.0;
    const double y = std::sin(1.3 * a) * std::cos(0.7 * b) + 0.5 * a * b;
    const double ga = 1.3 * std::cos(1.3 * a) * std::cos(0.7 * b) + 0.5 * b;
    const double gb = -0.7 * std::sin(1.3 * a) * std::sin(0.7 * b) + 0.5 * a;
    const bool val = q < n_val;
    (val ? job.y_val : job.y_train).push_back(float(y));
    (val ? job.x_val : job.x_train).push_back(float(a));
    (val ? job.g_val : job.g_train).push_back(float(ga));
    if (d == 2) {
      (val ? job.x_val : job.x_train).push_back(float(b));
      (val ? job.g_val : job.g_train).push_back(float(gb));
    }
  }
  job.n_val = n_val;
  job.n_train = n - n_val;
  job.init_params.resize(job.desc.num_params());
  std::uniform_real_distribution<float> u(-1, 1);
  for (int l = 0; l < job.desc.num_layers(); ++l) {
    const float bound = 1.f / std::sqrt(float(job.desc.layer_in(l)));
    const int cnt = job.desc.layer_out(l) * (job.desc.layer_in(l) + 1);
    for (int i = 0; i < cnt; ++i) job.init_params[job.desc.weight_offset(l) + i] = bound * u(rng);
  }
  job.x_rest[0] = 0.f;
  job.curvature_rest[0] = d == 1 ? -1.69f : NAN;
  return job;
}

cpu::LossOptions polish_loss() {
  cpu::LossOptions o;
  o.w = LossWeights{1.0, 0.05, 0.0, 0.0, 0.0};
  return o;
}

template <class T>
std::vector<T> as(const std::vector<float>& v) {
  return std::vector<T>(v.begin(), v.end());
}

// One full-batch loss and gradient of the polish (L_Z + w_F L_F with per-point weights), on
// cpu::mlp_loss_grad at jet order 1 or (fused) on the polish's fused kernel
// (cpu::fused_data_loss_grad), which the default recipe's polish runs. Argument: d (1: double,
// 2: float, as the default recipe).
template <class T, bool fused>
void loss_eval(benchmark::State& st, int d) {
  const NetworkJob job = make_problem(d);
  const std::vector<T> x = as<T>(job.x_train), y = as<T>(job.y_train), g = as<T>(job.g_train),
                       p = as<T>(job.init_params);
  std::vector<T> wt(job.n_train, T(1)), grad(p.size());
  const cpu::LossBatch<T> b{job.n_train, x.data(), y.data(), g.data(), 0, nullptr, nullptr, wt.data()};
  const cpu::LossOptions o = polish_loss();
  cpu::LossWorkspace<T> ws;
  cpu::FusedWorkspace<T> fws;
  for (auto _ : st) {
    const cpu::LossValues v = fused ? cpu::fused_data_loss_grad<T>(job.desc, p.data(), b, o.w, grad.data(), fws)
                                    : cpu::mlp_loss_grad<T>(job.desc, p.data(), b, o, grad.data(), ws, 1);
    benchmark::DoNotOptimize(v.total);
    benchmark::DoNotOptimize(grad.data());
  }
  st.counters["points/s"] = benchmark::Counter(double(job.n_train) * st.iterations(), benchmark::Counter::kIsRate);
  st.SetLabel(d == 1 ? "1D Net-3 double, 91 points" : "2D Net-2 float, 865 points");
}
void BM_PolishLoss(benchmark::State& st) {
  if (st.range(0) == 1) loss_eval<double, false>(st, 1);
  else loss_eval<float, false>(st, 2);
}
BENCHMARK(BM_PolishLoss)->Arg(1)->Arg(2);
void BM_PolishLossFused(benchmark::State& st) {
  if (st.range(0) == 1) loss_eval<double, true>(st, 1);
  else loss_eval<float, true>(st, 2);
}
BENCHMARK(BM_PolishLossFused)->Arg(1)->Arg(2);

// The validation loss the polish measures after every accepted step: the fused kernel's loss
// without the gradient on the validation split (1D: 10 points in double, 2D: 96 in float).
template <class T>
void val_eval(benchmark::State& st, int d) {
  const NetworkJob job = make_problem(d);
  const std::vector<T> x = as<T>(job.x_val), y = as<T>(job.y_val), g = as<T>(job.g_val), p = as<T>(job.init_params);
  std::vector<T> wt(job.n_val, T(1));
  const cpu::LossBatch<T> b{job.n_val, x.data(), y.data(), g.data(), 0, nullptr, nullptr, wt.data()};
  cpu::FusedWorkspace<T> fws;
  for (auto _ : st) benchmark::DoNotOptimize(cpu::fused_data_loss_grad<T>(job.desc, p.data(), b, polish_loss().w, nullptr, fws).total);
}
void BM_PolishValLoss(benchmark::State& st) {
  if (st.range(0) == 1) val_eval<double>(st, 1);
  else val_eval<float>(st, 2);
}
BENCHMARK(BM_PolishValLoss)->Arg(1)->Arg(2);

// The 1D rest penalty with its gradient: the jet of one point at order 2, forward and reverse.
void BM_PolishRest(benchmark::State& st) {
  const NetworkJob job = make_problem(1);
  const std::vector<double> p = as<double>(job.init_params);
  std::vector<double> grad(p.size(), 0.0);
  cpu::JetWorkspace<double> jw;
  const double xr[1] = {0.0};
  for (auto _ : st) {
    double jet[4], dj[4] = {0, 0, 0, 0};
    cpu::mlp_jet_forward<double>(job.desc, p.data(), xr, 1, 2, jet, jw);
    const double r = jet[2] + 1.69;
    dj[2] = 0.2 * r;
    cpu::mlp_jet_backward<double>(job.desc, p.data(), xr, 1, 2, dj, grad.data(), jw);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_PolishRest);

// The two-loop recursion with a full memory of 10 pairs, 1153 weights (Net-2).
void BM_LbfgsDirection(benchmark::State& st) {
  const int P = 1153, m = 10;
  std::mt19937 rng(2);
  std::normal_distribution<double> nd;
  std::deque<Eigen::VectorXd> S, Y;
  std::deque<double> rho;
  for (int i = 0; i < m; ++i) {
    Eigen::VectorXd s(P), y(P);
    for (int k = 0; k < P; ++k) s[k] = nd(rng), y[k] = s[k] * (1.5 + 0.5 * std::sin(k)) + 0.01 * nd(rng);
    rho.push_back(1.0 / s.dot(y));
    S.push_back(s);
    Y.push_back(y);
  }
  Eigen::VectorXd g(P), p(P);
  for (int k = 0; k < P; ++k) g[k] = nd(rng);
  std::vector<double> alpha(m);
  for (auto _ : st) {
    lbfgs_direction(g, S, Y, rho, alpha, p);
    benchmark::DoNotOptimize(p.data());
  }
}
BENCHMARK(BM_LbfgsDirection);

// A whole polish of range(1) iterations (no early stop: keep_best on, tolerance as the recipe)
// of one network on the CPU, the default recipe's options. Time per iteration in the counter.
void BM_PolishNetwork(benchmark::State& st) {
  const int d = int(st.range(0)), iters = int(st.range(1));
  const NetworkJob job = make_problem(d);
  TrainConfig cfg;
  cfg.loss = polish_loss();
  PolishOptions po;
  po.iterations = po.iterations_1d = iters;
  po.w_c = po.w_s = 0;
  po.relative_floor[0] = 0.1;
  po.rest_weight = 0.1;
  int done = 0;
  for (auto _ : st) {
    std::vector<float> p = job.init_params;
    const PolishResult r = polish_network(job, cfg, po, p);
    done += r.iterations;
    benchmark::DoNotOptimize(p.data());
  }
  st.counters["us/iteration"] = benchmark::Counter(double(done) * 1e-6, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_PolishNetwork)->Args({1, 500})->Args({2, 500})->Unit(benchmark::kMillisecond);

#ifdef YARNHOM_HAVE_CUDA
// The GPU polish of 14 networks (5 1D, 9 2D, as the synthetic dataset's terms) in one launch,
// range(0) iterations each (the default precisions: 1D double, 2D float). Wall time of
// cuda_polish_networks (upload, the launch, download); us/iteration: per iteration of the
// longest polish.
void BM_CudaPolish(benchmark::State& st) {
  if (cuda::device_count() == 0) {
    st.SkipWithError("no CUDA GPU");
    return;
  }
  const int iters = int(st.range(0));
  std::vector<NetworkJob> jobs;
  for (int j = 0; j < 14; ++j) jobs.push_back(make_problem(j < 5 ? 1 : 2, uint32_t(j + 1)));
  TrainConfig cfg;
  cfg.loss = polish_loss();
  PolishOptions po;
  po.iterations = po.iterations_1d = iters;
  po.w_c = po.w_s = 0;
  po.relative_floor[0] = 0.1;
  po.rest_weight = 0.1;
  std::vector<int> which;
  for (int j = 0; j < 14; ++j) which.push_back(j);
  int done = 0;
  for (auto _ : st) {
    std::vector<std::vector<float>> params;
    for (auto& j : jobs) params.push_back(j.init_params);
    std::vector<PolishResult> res(14);
    cuda_polish_networks(jobs, cfg, po, which, params, res);
    int longest = 0;
    for (auto& r : res) longest = std::max(longest, r.iterations);
    done += longest;
  }
  st.counters["us/iteration"] = benchmark::Counter(double(done) * 1e-6, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CudaPolish)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
#endif

}  // namespace

BENCHMARK_MAIN();
