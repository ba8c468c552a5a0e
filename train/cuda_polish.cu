// The L-BFGS polish on the GPU (train/cuda_polish.hpp): train/lbfgs.hpp's lbfgs_minimize and
// train/polish.cpp's polish_in, statement by statement, as one kernel in which a cluster of CB
// thread blocks polishes one network from its first evaluation to its last iterate. Every
// network of the run is one cluster of the same launch, so the whole polish is one launch and
// one synchronization, however many iterations it takes.
//
// Inside a cluster the work of an evaluation (the fused loss and gradient of the full training
// split, cuda/polish_jet.cuh) is cut into chunks of points, dealt round-robin to the blocks;
// each block sums its chunks' gradients in chunk order in its shared memory, and after a
// cluster barrier every block sums the CB partial gradients in rank order, so every block holds
// the same gradient, bit for bit. Every block then runs the optimizer itself, redundantly and
// identically: its own copy of x, g, the direction and the history pairs (in global memory,
// double, as on the CPU), the two-loop recursion (in warp 0: about 21 dot products of ~1,100
// entries, each a lane-strided sum and a fixed shuffle tree), and the line search's scalar
// logic (in every thread: all of them see the same values and take the same branches). So no
// decision is ever communicated, and the blocks leave the loop together. The only cross-block
// traffic is the distributed shared memory read of the partial gradients and loss sums, double
// buffered by the parity of a collective counter so that one barrier per evaluation suffices
// (the scheme of the epoch kernel, train/cuda_backend.cu).
//
// The losses are computed in T (double for the 1D terms, float for the 2D terms by default:
// PolishOptions::in_double), the optimizer in double, as on the CPU; with T = double the device
// and the CPU polish follow the same iterates up to the rounding of sums taken in another order.
#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "cuda/api.hpp"
#include "cuda/check.cuh"
#include "cuda/polish_lbfgs.cuh"
#include "train/cuda_polish.hpp"

namespace yarnhom {
namespace cuda {
namespace {

using namespace polish;

__global__ void __launch_bounds__(kThreads) polish_kernel(const PolNet* nets) {
  extern __shared__ double smem_d[];
  __shared__ double red[64];
  const int j = blockIdx.x / int(cg::this_cluster().num_blocks());
  const PolNet& n = nets[j];
  if (n.dbl) {
    if (n.s.d == 1) polish_body<double, 1>(n, smem_d, red);
    else polish_body<double, 2>(n, smem_d, red);
  } else {
    if (n.s.d == 1) polish_body<float, 1>(n, smem_d, red);
    else polish_body<float, 2>(n, smem_d, red);
  }
}

// The optimizer's five vectors (double), then the loss's buffers (polish_layout, in T).
size_t smem_bytes(const NetShape& s, bool dbl) {
  const size_t vecs = size_t(5) * ((s.P + 3) & ~3) * 8;
  return vecs + (dbl ? size_t(polish_layout<double>(s).total) * 8 : size_t(polish_layout<float>(s).total) * 4);
}

}  // namespace
}  // namespace cuda

namespace {

double resolved_weight(double polish_w, double epoch_w) { return polish_w >= 0 ? polish_w : epoch_w; }

const char* stop_text(int s) {
  switch (s) {
    case cuda::kNonFiniteStart: return "non-finite objective at the start";
    case cuda::kZeroGradient: return "zero gradient";
    case cuda::kNoProgress: return kPolishNoProgress;
    case cuda::kConverged: return "converged (relative decrease below tolerance)";
    default: return "iteration limit";
  }
}

// The device's shared memory per block available to the kernel's dynamic part.
size_t smem_budget() {
  int dev = 0, optin = 0;
  cuda::check(cudaGetDevice(&dev), "cudaGetDevice");
  cuda::check(cudaDeviceGetAttribute(&optin, cudaDevAttrMaxSharedMemoryPerBlockOptin, dev), "cudaDeviceGetAttribute");
  return size_t(optin) - 64 * 8 - cuda::kMaxMemory * 8 - 1024;  // the static red[] and rho[], and a margin
}

}  // namespace

bool cuda_polish_supports(const NetworkJob& job, const TrainConfig& cfg, const PolishOptions& opt) {
  const int d = job.desc.input_dim;
  if (resolved_weight(opt.w_c, cfg.loss.w.c) != 0 || resolved_weight(opt.w_s, cfg.loss.w.s) != 0) return false;
  if (cfg.loss.w.x != 0 || job.desc.hidden.empty()) return false;
  const int memory = polish_memory(opt, d);
  if (memory < 1 || memory > cuda::kMaxMemory) return false;
  if (d == 2 && opt.rest_weight_2d > 0) return false;
  if (cuda::device_count() == 0) return false;
  const cuda::detail::NetShape s = cuda::detail::make_shape(job.desc);
  return cuda::smem_bytes(s, opt.in_double[d == 1 ? 0 : 1]) <= smem_budget();
}

namespace {

// One launch: the polishes of `which`, each in its configured precision, or all in double.
void launch_polish(const std::vector<NetworkJob>& jobs, const TrainConfig& cfg, const PolishOptions& opt,
                   const std::vector<int>& which, std::vector<std::vector<float>>& params,
                   std::vector<PolishResult>& results, bool all_double) {
  using cuda::check;
  if (which.empty()) return;
  cuda::require_device();
  const auto t0 = std::chrono::steady_clock::now();
  const int J = int(which.size());
  // One host buffer of everything the kernel reads (8-byte aligned pieces), one upload.
  std::vector<char> blob;
  auto put_bytes = [&](const void* src, size_t bytes) {
    const size_t at = (blob.size() + 15) & ~size_t(15);
    blob.resize(at + std::max<size_t>(bytes, 16));
    if (bytes) std::memcpy(blob.data() + at, src, bytes);
    return at;
  };
  auto put_as = [&](const std::vector<float>& v, bool dbl) {
    if (!dbl) return put_bytes(v.data(), v.size() * sizeof(float));
    std::vector<double> w(v.begin(), v.end());
    return put_bytes(w.data(), w.size() * sizeof(double));
  };
  struct Offs {
    size_t x, y, g, wt, xv, yv, gv, wtv, p0;
    bool has_wt;
  };
  std::vector<cuda::PolNet> nets(J);
  std::vector<Offs> offs(J);
  size_t smem = 0, vec_doubles = 0, loss_doubles = 0, best_floats = 0;
  std::vector<size_t> vec_at(J), loss_at(J), best_at(J);
  for (int q = 0; q < J; ++q) {
    const NetworkJob& job = jobs[which[q]];
    const int d = job.desc.input_dim;
    const bool dbl = all_double || opt.in_double[d == 1 ? 0 : 1];
    cuda::PolNet& n = nets[q];
    n = cuda::PolNet{};
    n.s = cuda::detail::make_shape(job.desc);
    n.dbl = dbl;
    n.n_train = job.n_train;
    n.n_val = job.n_val;
    n.max_iter = d == 1 && opt.iterations_1d >= 0 ? opt.iterations_1d : opt.iterations;
    n.memory = polish_memory(opt, d);
    n.keep_best = opt.keep_best;
    n.wz = cfg.loss.w.z;
    n.wf = cfg.loss.w.f;
    n.c1 = 1e-4, n.c2 = 0.9, n.rel_tol = 1e-12, n.max_search = 25;  // LbfgsOptions' defaults
    // The rest penalty (polish_in's rest_penalty): 1D, finite x_rest and curvature.
    n.rest = d == 1 && opt.rest_weight > 0 && std::isfinite(job.x_rest[0]) && std::isfinite(job.curvature_rest[0]);
    n.rest_w = opt.rest_weight;
    n.rest_k = job.curvature_rest[0];
    n.x_rest = double(job.x_rest[0]);
    const double floor = opt.relative_floor[d == 1 ? 0 : 1];
    std::vector<float> wt, wtv;
    if (floor > 0) {
      const RelativeFitScale sc = relative_fit_scale(job.g_train, d, floor);
      wt = relative_fit_weights(job.g_train, d, floor, sc);
      wtv = relative_fit_weights(job.g_val, d, floor, sc);
    }
    Offs& o = offs[q];
    o.x = put_as(job.x_train, dbl), o.y = put_as(job.y_train, dbl), o.g = put_as(job.g_train, dbl);
    o.xv = put_as(job.x_val, dbl), o.yv = put_as(job.y_val, dbl), o.gv = put_as(job.g_val, dbl);
    o.has_wt = floor > 0;
    o.wt = put_as(wt, dbl), o.wtv = put_as(wtv, dbl);
    o.p0 = put_bytes(params[which[q]].data(), params[which[q]].size() * sizeof(float));
    smem = std::max(smem, cuda::smem_bytes(n.s, dbl));
    vec_at[q] = vec_doubles;
    vec_doubles += size_t(cuda::kMaxCluster) * (2 * n.memory) * n.s.P;
    loss_at[q] = loss_doubles;
    loss_doubles += 2 * size_t(std::max(1, n.max_iter));
    best_at[q] = best_floats;
    best_floats += n.s.P;
  }
  cuda::DeviceVec<float> in_d((blob.size() + 3) / 4), best_d(best_floats + 1);
  cuda::DeviceVec<float> vec_d(2 * vec_doubles + 2), loss_d(2 * loss_doubles + 2);
  cuda::DeviceVec<float> out_d((sizeof(cuda::PolOut) * J + 3) / 4), nets_d((sizeof(cuda::PolNet) * J + 3) / 4);
  check(cudaMemcpy(in_d.data(), blob.data(), blob.size(), cudaMemcpyHostToDevice), "cudaMemcpy of the polish's data");
  const char* base = reinterpret_cast<const char*>(in_d.data());
  double* vec = reinterpret_cast<double*>(vec_d.data());
  double* loss = reinterpret_cast<double*>(loss_d.data());
  cuda::PolOut* out = reinterpret_cast<cuda::PolOut*>(out_d.data());
  for (int q = 0; q < J; ++q) {
    cuda::PolNet& n = nets[q];
    const Offs& o = offs[q];
    n.x = base + o.x, n.y = base + o.y, n.g = base + o.g;
    n.xv = base + o.xv, n.yv = base + o.yv, n.gv = base + o.gv;
    n.wt = o.has_wt ? base + o.wt : nullptr;
    n.wtv = o.has_wt ? base + o.wtv : nullptr;
    n.p0 = reinterpret_cast<const float*>(base + o.p0);
    n.vec = vec + vec_at[q];
    n.best = best_d.data() + best_at[q];
    n.train_loss = loss + loss_at[q];
    n.val_loss = n.train_loss + std::max(1, n.max_iter);
    n.out = out + q;
  }
  check(cudaMemcpy(nets_d.data(), nets.data(), sizeof(cuda::PolNet) * J, cudaMemcpyHostToDevice), "cudaMemcpy");
  check(cudaFuncSetAttribute(cuda::polish_kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, int(smem)),
        "cudaFuncSetAttribute (polish, shared memory " + std::to_string(smem) + " bytes)");
  // Blocks per network: the largest cluster (8, 4, 2, 1) for which every network's cluster is
  // resident at once (YARNHOM_CUDA_POLISH_CLUSTER caps it).
  const char* env = std::getenv("YARNHOM_CUDA_POLISH_CLUSTER");
  int want = env ? std::max(1, std::min(cuda::kMaxCluster, std::atoi(env))) : cuda::kMaxCluster;
  cudaLaunchConfig_t lc{};
  cudaLaunchAttribute attr[1];
  int CB = 1;
  for (int cb = want; cb >= 1; cb /= 2) {
    lc.gridDim = dim3(unsigned(J * cb));
    lc.blockDim = dim3(unsigned(cuda::kThreads));
    lc.dynamicSmemBytes = smem;
    attr[0].id = cudaLaunchAttributeClusterDimension;
    attr[0].val.clusterDim.x = unsigned(cb);
    attr[0].val.clusterDim.y = attr[0].val.clusterDim.z = 1;
    lc.attrs = attr;
    lc.numAttrs = 1;
    int clusters = 0;
    if (cudaOccupancyMaxActiveClusters(&clusters, cuda::polish_kernel, &lc) != cudaSuccess) {
      cudaGetLastError();
      continue;
    }
    if (clusters >= J || cb == 1) {
      CB = cb;
      break;
    }
  }
  lc.gridDim = dim3(unsigned(J * CB));
  attr[0].val.clusterDim.x = unsigned(CB);
  check(cudaLaunchKernelEx(&lc, cuda::polish_kernel, reinterpret_cast<const cuda::PolNet*>(nets_d.data())),
        "launch of the polish kernel (" + std::to_string(J) + " clusters of " + std::to_string(CB) + " blocks)");
  check(cudaGetLastError(), "launch of the polish kernel");
  cuda::synchronize();
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<cuda::PolOut> outs(J);
  check(cudaMemcpy(outs.data(), out, sizeof(cuda::PolOut) * J, cudaMemcpyDeviceToHost), "cudaMemcpy");
  std::vector<double> losses(loss_doubles);
  check(cudaMemcpy(losses.data(), loss, sizeof(double) * loss_doubles, cudaMemcpyDeviceToHost), "cudaMemcpy");
  std::vector<float> best(best_floats);
  check(cudaMemcpy(best.data(), best_d.data(), sizeof(float) * best_floats, cudaMemcpyDeviceToHost), "cudaMemcpy");
  if (std::getenv("YARNHOM_CUDA_POLISH_PROFILE")) {
    // Where block 0 of each cluster spent its SM clock cycles, per iteration.
    std::fprintf(stderr, "polish on the GPU: %d clusters of %d blocks, %.3f s\n", J, CB, sec);
    for (int q = 0; q < J; ++q) {
      const cuda::PolOut& o = outs[q];
      const double it = std::max(1, o.iterations);
      std::fprintf(stderr, "  %-3s %5d it %5d ev  kcycles/iteration: direction %.1f, line search %.1f, validation %.1f, "
                   "rest %.1f\n", jobs[which[q]].name.c_str(), o.iterations, o.evaluations, o.cycles[0] / it / 1e3,
                   o.cycles[1] / it / 1e3, o.cycles[2] / it / 1e3, o.cycles[3] / it / 1e3);
    }
  }
  for (int q = 0; q < J; ++q) {
    const int j = which[q];
    const cuda::PolOut& o = outs[q];
    PolishResult& r = results[j];
    r = PolishResult{};
    r.iterations = o.iterations;
    r.evaluations = o.evaluations;
    r.best_iteration = o.best_iteration;
    r.train_start = o.f0;
    r.val_start = o.val_start;
    r.val_end = o.val_best;
    r.stop = stop_text(o.stop);
    const double* tl = losses.data() + loss_at[q];
    r.train_loss.assign(tl, tl + o.iterations);
    r.val_loss.assign(tl + std::max(1, nets[q].max_iter), tl + std::max(1, nets[q].max_iter) + o.iterations);
    r.train_end = r.best_iteration > 0 ? r.train_loss[r.best_iteration - 1] : o.f0;
    r.seconds = sec;
    params[j].assign(best.begin() + best_at[q], best.begin() + best_at[q] + nets[q].s.P);
  }
}

}  // namespace

void cuda_polish_networks(const std::vector<NetworkJob>& jobs, const TrainConfig& cfg, const PolishOptions& opt,
                          const std::vector<int>& which, std::vector<std::vector<float>>& params,
                          std::vector<PolishResult>& results) {
  if (which.empty()) return;
  auto in_float = [&](int j) { return !opt.in_double[jobs[j].desc.input_dim == 1 ? 0 : 1]; };
  std::vector<std::vector<float>> again(params.size());  // the float polishes' starts
  for (int j : which)
    if (in_float(j)) again[j] = params[j];
  launch_polish(jobs, cfg, opt, which, params, results, false);
  // polish_network's rule: a float polish stalled high runs again in double from its start, in
  // one more launch, and the one with the lower validation loss is kept.
  std::vector<int> retry;
  for (int j : which)
    if (in_float(j) && polish_stalled_high(results[j], opt) &&
        cuda::smem_bytes(cuda::detail::make_shape(jobs[j].desc), true) <= smem_budget())
      retry.push_back(j);
  if (retry.empty()) return;
  std::vector<PolishResult> second(results.size());
  launch_polish(jobs, cfg, opt, retry, again, second, true);
  for (int j : retry) results[j] = choose_polish_retry(std::move(results[j]), std::move(second[j]), params[j], again[j]);
}

}  // namespace yarnhom
