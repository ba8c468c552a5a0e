// The CUDA backend (train/backend.hpp): every network of the run trains at once, one thread
// block per network, one kernel launch per epoch for all of them, and one host synchronization
// per epoch (the trainer steps ReduceLROnPlateau on the host between epochs and needs the
// losses).
//
// What one block does in an epoch is exactly what train/cpu_backend.cpp's epoch_one does for
// its network: the shuffled order of the training points (train/epoch_plan.hpp), batches of
// batch_size with the last one short, the batch's off-domain points drawn from
// batch_offdomain_key with the same counter-based generator, the fused loss and gradient of the
// batch (cuda/jet_block.cuh: the twin of cpu::mlp_loss_grad), PyTorch Adam with its step
// count, the epoch means of the training losses, and the validation losses on the job's
// validation split with its fixed off-domain points. The weights, Adam moments and gradient
// live in the block's shared memory for the whole epoch.
//
// Determinism: no atomics; every sum has a fixed order (see cuda/jet_block.cuh), so the same
// seed gives bit-identical weights run after run on the same GPU model and launch shape.
//
// Fault injection for tests (environment variable YARNHOM_CUDA_FAULT): "oom" asks cudaMalloc
// for more than the GPU has; "launch" launches the epoch kernel with an impossible block size.
// Both exercise the real error paths.
#include <cooperative_groups.h>
#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "cuda/adam.cuh"
#include "cuda/api.hpp"
#include "cuda/check.cuh"
#include "cuda/jet_block.cuh"
#include "train/cuda_backend.hpp"
#include "train/cuda_polish.hpp"
#include "train/epoch_plan.hpp"

namespace yarnhom {
namespace cuda {
namespace {

using namespace detail;
namespace cg = cooperative_groups;

// One network's device state; the array of these lives on the device.
struct NetDev {
  NetShape s;
  LossCfg cfg;
  uint64_t key;
  int batch, n_train, n_val, k_off, k_val;
  const float *x, *y, *g, *xv, *yv, *gv, *xov, *nov;
  float *p, *m, *v;
  int *order, *swapj;
  long long step;  // Adam steps taken (device-owned)
};

// Per epoch from the host: learning rate and whether the network trains.
struct EpochCtl {
  double lr;
  int active;
  int pad;
};

// Per epoch to the host: train means and validation values (total, z, f, c, s, x).
struct EpochOut {
  double train[6], val[6];
};

// Threads per block: 512 (at most 128 registers a thread) or 256 (no register cap that spills);
// environment variable YARNHOM_CUDA_THREADS picks, default below.
constexpr int kDefaultThreads = 256;
constexpr int kMaxCluster = 8;

// Fisher-Yates of train/epoch_plan.hpp's shuffled_order, with the random draws (which depend
// only on the index) computed in parallel and the swaps done by one thread.
// Each block of a network's cluster shuffles its own copy (no dependency between blocks).
__device__ void shuffle(const NetDev& n, int epoch, int* o, int* swapj) {
  const int N = n.n_train;
  const uint64_t k = rng_key(n.key, kRngShuffle, uint64_t(epoch));
  for (int i = threadIdx.x; i < N; i += blockDim.x) {
    o[i] = i;
    swapj[i] = i > 0 ? static_cast<int>(rng_uniform(k, uint64_t(i)) * (i + 1)) : 0;
  }
  __syncthreads();
  if (threadIdx.x == 0) {
    for (int i = N - 1; i > 0; --i) {
      const int j = swapj[i];
      const int t = o[i];
      o[i] = o[j];
      o[j] = t;
    }
  }
  __syncthreads();
}

template <int D, int ORDER>
__device__ void epoch_body(NetDev& n, const NetShape& s, const LossCfg& cfg, int epoch, double lr, EpochOut* out,
                           float* sm, int S) {
  __shared__ Sums5 sums[2];  // this block's loss sums, double-buffered by batch parity
  __shared__ float adam_c[2];
  __shared__ double acc[6];
  cg::cluster_group cl = cg::this_cluster();
  const int rank = int(cl.block_rank()), CB = int(cl.num_blocks());
  const int P = s.P, P4 = (P + 3) & ~3;
  float* W = sm;
  float* M = sm + P4;
  float* V = sm + 2 * P4;
  float* Gb[2] = {sm + 3 * P4, sm + 4 * P4};  // this block's partial gradient, by batch parity
  for (int i = threadIdx.x; i < P; i += blockDim.x) {
    W[i] = n.p[i];
    M[i] = n.m[i];
    V[i] = n.v[i];
  }
  Chunk ch = make_chunk(sm, chunk_layout(s, S, 5 * P4), S);
  if (threadIdx.x < 6) acc[threadIdx.x] = 0.0;
  int* order = n.order + size_t(rank) * n.n_train;
  shuffle(n, epoch, order, n.swapj + size_t(rank) * n.n_train);

  const int N = n.n_train, B = n.batch;
  const int batches = (N + B - 1) / B;
  const float b1 = 0.9f, b2 = 0.999f, one_b1 = float(1.0 - 0.9), one_b2 = float(1.0 - 0.999), eps = 1e-8f;
  const float inv_k = n.k_off > 0 ? 1.f / float(n.k_off) : 0.f;
  long long step = n.step;
  for (int b = 0; b < batches; ++b) {
    float* G = Gb[b & 1];
    Sums5* sum = &sums[b & 1];
    const int begin = b * B, m = min(B, N - begin);
    for (int i = threadIdx.x; i < P; i += blockDim.x) G[i] = 0.f;
    if (threadIdx.x == 0) *sum = Sums5{};
    BatchSrc src;
    src.m = m, src.x = n.x, src.y = n.y, src.g = n.g, src.idx = order + begin;
    src.k = cfg.ws != 0 ? n.k_off : 0;
    src.okey = batch_offdomain_key(n.key, epoch, b);
    const float inv_m = 1.f / float(m);
    __syncthreads();
    // The batch's tasks (data chunks, then off-domain chunks) go round-robin to the blocks of
    // the cluster; each block sums its tasks' gradients in task order.
    batch_tasks<D, ORDER>(s, W, cfg, src, inv_m, inv_k, ch, G, sum, rank, CB);
    cl.sync();  // every block's partial gradient and sums are complete (and visible)
    ++step;
    if (threadIdx.x == 0) {
      Sums5 t;
      for (int r = 0; r < CB; ++r) {
        const Sums5 q = *cl.map_shared_rank(sum, r);
        t.z += q.z, t.f += q.f, t.c += q.c, t.s += q.s, t.x += q.x;
      }
      const double bc1 = 1.0 - pow(0.9, double(step));
      const double bc2 = 1.0 - pow(0.999, double(step));
      adam_c[0] = float(lr / bc1);
      adam_c[1] = float(sqrt(bc2));
      const double vz = double(t.z) * double(inv_m), vf = double(t.f) * double(inv_m),
                   vc = double(t.c) * double(inv_m), vx = double(t.x) * double(inv_m),
                   vs = double(t.s) * double(inv_k);
      acc[0] += cfg.wz * vz + cfg.wf * vf + cfg.wc * vc + cfg.ws * vs + cfg.wx * vx;
      acc[1] += vz, acc[2] += vf, acc[3] += vc, acc[4] += vs, acc[5] += vx;
    }
    __syncthreads();
    // The gradient: the blocks' partial gradients summed in rank order, the same in every
    // block; every block then takes the same Adam step on its own copy of the weights
    // (cpu/adam.hpp; bias corrections in double; no FMA contraction). The other parity's
    // buffers are next written after the next cluster barrier, so one barrier per batch is
    // enough.
    const float step_size = adam_c[0], bc2_sqrt = adam_c[1];
    for (int i = threadIdx.x; i < P; i += blockDim.x) {
      float gi = 0.f;
      for (int r = 0; r < CB; ++r) gi = r == 0 ? cl.map_shared_rank(G, r)[i] : gi + cl.map_shared_rank(G, r)[i];
      cuda::detail::adam_step(W[i], M[i], V[i], gi, b1, b2, one_b1, one_b2, eps, step_size, bc2_sqrt);
    }
    __syncthreads();
  }
  // Validation: the same fused pass without the gradient, its tasks spread over the cluster.
  Sums5* vsum = &sums[batches & 1];
  if (threadIdx.x == 0) *vsum = Sums5{};
  BatchSrc val;
  val.m = n.n_val, val.x = n.xv, val.y = n.yv, val.g = n.gv;
  val.k = cfg.ws != 0 ? n.k_val : 0;
  val.xo = n.xov, val.no = n.nov;
  const float vinv_m = n.n_val > 0 ? 1.f / float(n.n_val) : 0.f;
  const float vinv_k = n.k_val > 0 ? 1.f / float(n.k_val) : 0.f;
  __syncthreads();
  batch_tasks<D, ORDER>(s, W, cfg, val, vinv_m, vinv_k, ch, nullptr, vsum, rank, CB);
  cl.sync();
  if (rank == 0) {
    for (int i = threadIdx.x; i < P; i += blockDim.x) {
      n.p[i] = W[i];
      n.m[i] = M[i];
      n.v[i] = V[i];
    }
    if (threadIdx.x == 0) {
      Sums5 t;
      for (int r = 0; r < CB; ++r) {
        const Sums5 q = *cl.map_shared_rank(vsum, r);
        t.z += q.z, t.f += q.f, t.c += q.c, t.s += q.s, t.x += q.x;
      }
      n.step = step;
      const double inv = 1.0 / batches;
      for (int q = 0; q < 6; ++q) out->train[q] = acc[q] * inv;
      const double vz = double(t.z) * double(vinv_m), vf = double(t.f) * double(vinv_m),
                   vc = double(t.c) * double(vinv_m), vx = double(t.x) * double(vinv_m),
                   vs = double(t.s) * double(vinv_k);
      out->val[0] = cfg.wz * vz + cfg.wf * vf + cfg.wc * vc + cfg.ws * vs + cfg.wx * vx;
      out->val[1] = vz, out->val[2] = vf, out->val[3] = vc, out->val[4] = vs, out->val[5] = vx;
    }
  }
  cl.sync();  // no block leaves while another may still read its shared memory
}

// Grid: one cluster of CB blocks per network (CB from the launch's cluster dimension).
template <int THREADS>
__global__ void __launch_bounds__(THREADS) epoch_kernel(NetDev* nets, const EpochCtl* ctl, EpochOut* out, int epoch, int S) {
  extern __shared__ float4 smem4[];
  __shared__ NetShape s;
  __shared__ LossCfg cfg;
  float* sm = reinterpret_cast<float*>(smem4);
  const int j = blockIdx.x / int(cg::this_cluster().num_blocks());
  if (!ctl[j].active) return;  // the whole cluster returns
  NetDev& n = nets[j];
  if (threadIdx.x == 0) {
    s = n.s;
    cfg = n.cfg;
  }
  __syncthreads();
  const double lr = ctl[j].lr;
  const int d = s.d, o = cfg.order;
  if (d == 1) {
    if (o == 1) epoch_body<1, 1>(n, s, cfg, epoch, lr, out + j, sm, S);
    else if (o == 2) epoch_body<1, 2>(n, s, cfg, epoch, lr, out + j, sm, S);
    else epoch_body<1, 3>(n, s, cfg, epoch, lr, out + j, sm, S);
  } else {
    if (o == 1) epoch_body<2, 1>(n, s, cfg, epoch, lr, out + j, sm, S);
    else if (o == 2) epoch_body<2, 2>(n, s, cfg, epoch, lr, out + j, sm, S);
    else epoch_body<2, 3>(n, s, cfg, epoch, lr, out + j, sm, S);
  }
}

// Pinned host memory, freed on destruction.
template <class T>
struct Pinned {
  T* p = nullptr;
  void alloc(size_t n) {
    free();
    void* q = nullptr;
    check(cudaMallocHost(&q, n * sizeof(T)), "cudaMallocHost");
    p = static_cast<T*>(q);
  }
  void free() {
    if (p) cudaFreeHost(p);
    p = nullptr;
  }
  ~Pinned() { free(); }
};

class CudaBackend final : public Backend {
 public:
  std::string name() const override { return "cuda"; }

  ~CudaBackend() override {
    if (stream_) cudaStreamDestroy(stream_);
  }

  void setup(const std::vector<NetworkJob>& jobs, const TrainConfig& cfg) override {
    require_device();
    if (cfg.loss.stencil_c && cfg.loss.w.c != 0)
      throw std::invalid_argument("the CUDA backend computes L_C exactly; --stencil-c is CPU-only");
    if (cfg.adam.beta1 != 0.9 || cfg.adam.beta2 != 0.999 || cfg.adam.eps != 1e-8)
      throw std::invalid_argument("the CUDA backend implements Adam with betas (0.9, 0.999), eps 1e-8");
    const char* fault = std::getenv("YARNHOM_CUDA_FAULT");
    fault_ = fault ? fault : "";
    if (!stream_) check(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), "cudaStreamCreate");
    J_ = int(jobs.size());
    const int order = cpu::data_jet_order(cfg.loss);
    int dev = 0, optin = 0;
    check(cudaGetDevice(&dev), "cudaGetDevice");
    check(cudaDeviceGetAttribute(&optin, cudaDevAttrMaxSharedMemoryPerBlockOptin, dev), "cudaDeviceGetAttribute");
    if (fault_ == "oom") {
      size_t free_b = 0, total_b = 0;
      check(cudaMemGetInfo(&free_b, &total_b), "cudaMemGetInfo");
      bufs_.emplace_back();
      bufs_.back().resize(total_b / sizeof(float) * 2);  // throws: out of memory
    }
    std::vector<NetDev> host(J_);
    int need_params = 0;
    S_ = 0;
    for (int j = 0; j < J_; ++j) {
      const NetworkJob& job = jobs[j];
      if (job.init_params.size() != size_t(job.desc.num_params()))
        throw std::invalid_argument("initial weights do not match the network of " + job.name);
      NetDev& n = host[j];
      n.s = make_shape(job.desc);
      n.cfg.wz = cfg.loss.w.z, n.cfg.wf = cfg.loss.w.f, n.cfg.wc = cfg.loss.w.c, n.cfg.ws = cfg.loss.w.s,
      n.cfg.wx = cfg.loss.w.x;
      n.cfg.order = order;
      n.key = job.key;
      n.batch = job.batch_size;
      n.n_train = job.n_train;
      n.n_val = job.n_val;
      n.k_off = cfg.off_domain;
      n.k_val = int(job.xo_val.size()) / job.desc.input_dim;
      n.x = put(job.x_train), n.y = put(job.y_train), n.g = put(job.g_train);
      n.xv = put(job.x_val), n.yv = put(job.y_val), n.gv = put(job.g_val);
      n.xov = put(job.xo_val), n.nov = put(job.no_val);
      n.p = put(job.init_params);
      n.m = put(std::vector<float>(job.init_params.size(), 0.f));
      n.v = put(std::vector<float>(job.init_params.size(), 0.f));
      n.order = put_int(kMaxCluster * std::max(1, job.n_train));
      n.swapj = put_int(kMaxCluster * std::max(1, job.n_train));
      n.step = 0;
      need_params = std::max(need_params, 5 * ((n.s.P + 3) & ~3));
      shapes_.push_back(n.s);
    }
    // The largest chunk stride (4 mod 32) whose buffers fit the shared memory of one block.
    const int budget = optin / int(sizeof(float)) - 512;  // static shared memory of the kernel
    for (int S = 4; ; S += 32) {
      bool fits = true;
      for (const NetShape& s : shapes_)
        if (chunk_layout(s, S, need_params).total > budget) fits = false;
      if (!fits) break;
      S_ = S;
    }
    for (const NetShape& s : shapes_) {
      const int C = jet_channels(s.d, order);
      if (S_ < C) throw std::invalid_argument("the network is too wide for the CUDA backend's shared memory");
    }
    smem_ = size_t(0);
    for (const NetShape& s : shapes_) smem_ = std::max(smem_, size_t(chunk_layout(s, S_, need_params).total) * 4);
    const char* env_t = std::getenv("YARNHOM_CUDA_THREADS");
    threads_ = env_t && std::atoi(env_t) == 512 ? 512 : env_t && std::atoi(env_t) == 256 ? 256 : kDefaultThreads;
    for (auto k : {epoch_kernel<256>, epoch_kernel<512>})
      check(cudaFuncSetAttribute(k, cudaFuncAttributeMaxDynamicSharedMemorySize, int(smem_)),
            "cudaFuncSetAttribute (shared memory " + std::to_string(smem_) + " bytes)");
    // Blocks per network: a cluster of CB blocks shares a batch's chunks (cudaOccupancy says how
    // many clusters fit at once; all J must, or some networks would wait for others).
    const char* env_cb = std::getenv("YARNHOM_CUDA_CLUSTER");
    int want = env_cb ? std::atoi(env_cb) : 4;
    want = std::max(1, std::min(kMaxCluster, want));
    CB_ = 1;
    for (int cb = want; cb >= 1; cb /= 2) {
      cudaLaunchConfig_t lc = config(threads_, cb);
      int clusters = 0;
      const cudaError_t e = threads_ == 512 ? cudaOccupancyMaxActiveClusters(&clusters, epoch_kernel<512>, &lc)
                                            : cudaOccupancyMaxActiveClusters(&clusters, epoch_kernel<256>, &lc);
      if (e != cudaSuccess) {
        cudaGetLastError();
        continue;
      }
      if (clusters >= J_ || cb == 1) {
        CB_ = cb;
        break;
      }
    }
    nets_.resize(sizeof(NetDev) * J_ / sizeof(float) + 1);
    check(cudaMemcpy(nets_.data(), host.data(), sizeof(NetDev) * J_, cudaMemcpyHostToDevice), "cudaMemcpy");
    ctl_d_.resize(sizeof(EpochCtl) * J_ / sizeof(float) + 1);
    out_d_.resize(sizeof(EpochOut) * J_ / sizeof(float) + 1);
    ctl_h_.alloc(J_);
    out_h_.alloc(J_);
    host_ = host;
    check(cudaDeviceSynchronize(), "setup of the CUDA backend");
  }

  void run_epoch(int epoch, const std::vector<double>& lr, const std::vector<char>& active,
                 std::vector<EpochStats>& stats) override {
    const auto t0 = std::chrono::steady_clock::now();
    stats.resize(J_);
    bool any = false;
    for (int j = 0; j < J_; ++j) {
      ctl_h_.p[j] = EpochCtl{lr[j], active[j] ? 1 : 0, 0};
      any = any || active[j];
    }
    if (!any) return;
    check(cudaMemcpyAsync(ctl_d_.data(), ctl_h_.p, sizeof(EpochCtl) * J_, cudaMemcpyHostToDevice, stream_),
          "cudaMemcpyAsync");
    const int threads = fault_ == "launch" ? 4096 : threads_;
    launch(threads, epoch);
    check(cudaMemcpyAsync(out_h_.p, out_d_.data(), sizeof(EpochOut) * J_, cudaMemcpyDeviceToHost, stream_),
          "cudaMemcpyAsync");
    check(cudaStreamSynchronize(stream_), "the epoch kernel");
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (int j = 0; j < J_; ++j) {
      if (!active[j]) continue;
      EpochStats& st = stats[j];
      const EpochOut& o = out_h_.p[j];
      auto set = [](cpu::LossValues& v, const double* a) {
        v.total = a[0], v.z = a[1], v.f = a[2], v.c = a[3], v.s = a[4], v.x = a[5];
      };
      set(st.train, o.train);
      set(st.val, o.val);
      st.seconds = sec;  // all networks ran concurrently in this one launch
    }
  }

  // The polish on the device (train/cuda_polish.cu): every supported network in one launch.
  // YARNHOM_CUDA_POLISH=cpu leaves it to the CPU (for comparisons).
  std::vector<char> polish(const std::vector<NetworkJob>& jobs, const TrainConfig& cfg, const PolishOptions& opt,
                           const std::vector<int>& which, std::vector<std::vector<float>>& params,
                           std::vector<PolishResult>& results) override {
    std::vector<char> took(which.size(), 0);
    const char* env = std::getenv("YARNHOM_CUDA_POLISH");
    if (env && std::strcmp(env, "cpu") == 0) return took;
    std::vector<int> mine;
    for (size_t i = 0; i < which.size(); ++i)
      if (cuda_polish_supports(jobs[which[i]], cfg, opt)) {
        took[i] = 1;
        mine.push_back(which[i]);
      }
    cuda_polish_networks(jobs, cfg, opt, mine, params, results);
    return took;
  }

  std::vector<float> params(int j) override {
    std::vector<float> h(host_[j].s.P);
    check(cudaMemcpy(h.data(), host_[j].p, sizeof(float) * h.size(), cudaMemcpyDeviceToHost),
          "cudaMemcpy of the weights");
    return h;
  }

 private:
  float* put(const std::vector<float>& h) {
    bufs_.emplace_back();
    if (h.empty())
      bufs_.back().resize(1);
    else
      bufs_.back().upload(h);
    return bufs_.back().data();
  }
  cudaLaunchConfig_t config(int threads, int cb) {
    cudaLaunchConfig_t lc{};
    lc.gridDim = dim3(unsigned(J_ * cb));
    lc.blockDim = dim3(unsigned(threads));
    lc.dynamicSmemBytes = smem_;
    lc.stream = stream_;
    attr_[0].id = cudaLaunchAttributeClusterDimension;
    attr_[0].val.clusterDim.x = unsigned(cb);
    attr_[0].val.clusterDim.y = 1;
    attr_[0].val.clusterDim.z = 1;
    lc.attrs = attr_;
    lc.numAttrs = 1;
    return lc;
  }

  void launch(int threads, int epoch) {
    cudaLaunchConfig_t lc = config(threads, CB_);
    auto kernel = threads_ == 512 ? epoch_kernel<512> : epoch_kernel<256>;
    check(cudaLaunchKernelEx(&lc, kernel, reinterpret_cast<NetDev*>(nets_.data()),
                             reinterpret_cast<const EpochCtl*>(ctl_d_.data()),
                             reinterpret_cast<EpochOut*>(out_d_.data()), epoch, S_),
          "launch of the epoch kernel (" + std::to_string(J_) + " clusters of " + std::to_string(CB_) +
              " blocks of " + std::to_string(threads) + " threads)");
    check(cudaGetLastError(), "launch of the epoch kernel");
  }

  int* put_int(int n) {
    ibufs_.emplace_back(size_t(n));
    return ibufs_.back().data();
  }

  int J_ = 0, S_ = 0, CB_ = 1, threads_ = kDefaultThreads;
  cudaLaunchAttribute attr_[1];
  size_t smem_ = 0;
  std::string fault_;
  cudaStream_t stream_ = nullptr;
  std::vector<NetShape> shapes_;
  std::vector<NetDev> host_;
  std::vector<DeviceVec<float>> bufs_;
  std::vector<DeviceVec<int>> ibufs_;
  DeviceVec<float> nets_, ctl_d_, out_d_;
  Pinned<EpochCtl> ctl_h_;
  Pinned<EpochOut> out_h_;
};

}  // namespace
}  // namespace cuda

std::unique_ptr<Backend> make_cuda_backend() { return std::make_unique<cuda::CudaBackend>(); }

}  // namespace yarnhom
