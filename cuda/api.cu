// The CUDA twins of the cpu/ kernels (declared in cuda/api.hpp): thin multi-block launches of
// the block-level functions of cuda/jet_block.cuh.
#include <cuda_runtime.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "cuda/api.hpp"
#include "cuda/check.cuh"
#include "cuda/jet_block.cuh"
#include "cuda/mma_jet.cuh"

namespace yarnhom::cuda {

using namespace detail;

int device_count() {
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no device" error
    return 0;
  }
  return n;
}

std::string device_description() {
  int n = 0;
  const cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess) {
    cudaGetLastError();
    return std::string("no usable CUDA device (") + cudaGetErrorString(e) + ")";
  }
  if (n == 0) return "no CUDA device";
  int dev = 0;
  cudaGetDevice(&dev);
  cudaDeviceProp p{};
  cudaGetDeviceProperties(&p, dev);
  return std::string(p.name) + " (sm_" + std::to_string(p.major) + std::to_string(p.minor) + ", " +
         std::to_string(p.multiProcessorCount) + " SMs)";
}

void require_device() {
  int n = 0;
  const cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess) {
    cudaGetLastError();
    throw CudaError(std::string("the CUDA backend needs a GPU, and none is usable: ") + cudaGetErrorString(e));
  }
  if (n == 0) throw CudaError("the CUDA backend needs a GPU, and this machine has none");
}

void synchronize() { check(cudaDeviceSynchronize(), "cudaDeviceSynchronize"); }

// ---- DeviceVec ----
template <class T>
void DeviceVec<T>::resize(size_t n) {
  if (n == n_) return;
  release();
  if (n == 0) return;
  void* p = nullptr;
  check(cudaMalloc(&p, n * sizeof(T)), "cudaMalloc of " + std::to_string(n * sizeof(T)) + " bytes");
  p_ = static_cast<T*>(p);
  n_ = n;
}
template <class T>
void DeviceVec<T>::upload(const std::vector<T>& h) {
  resize(h.size());
  if (n_) check(cudaMemcpy(p_, h.data(), n_ * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy to the device");
}
template <class T>
std::vector<T> DeviceVec<T>::download() const {
  std::vector<T> h(n_);
  if (n_) check(cudaMemcpy(h.data(), p_, n_ * sizeof(T), cudaMemcpyDeviceToHost), "cudaMemcpy from the device");
  return h;
}
template <class T>
void DeviceVec<T>::fill_zero() {
  if (n_) check(cudaMemset(p_, 0, n_ * sizeof(T)), "cudaMemset");
}
template <class T>
void DeviceVec<T>::release() {
  if (p_) cudaFree(p_);
  p_ = nullptr;
  n_ = 0;
}
template class DeviceVec<float>;
template class DeviceVec<int>;

// ---- launch shape ----
namespace {

LaunchShape g_shape;

struct Launch {
  int threads, S, blocks;
  size_t smem;  // bytes
};

int sm_count() {
  static int n = [] {
    int dev = 0, v = 0;
    check(cudaGetDevice(&dev), "cudaGetDevice");
    check(cudaDeviceGetAttribute(&v, cudaDevAttrMultiProcessorCount, dev), "cudaDeviceGetAttribute");
    return v;
  }();
  return n;
}

int smem_optin() {
  static int n = [] {
    int dev = 0, v = 0;
    check(cudaGetDevice(&dev), "cudaGetDevice");
    check(cudaDeviceGetAttribute(&v, cudaDevAttrMaxSharedMemoryPerBlockOptin, dev), "cudaDeviceGetAttribute");
    return v;
  }();
  return n;
}

// Shared memory of a multi-block twin: params (and gradient) then the chunk buffers.
Launch pick_launch(const NetShape& s, int tasks, bool with_grad) {
  Launch l;
  l.threads = g_shape.threads > 0 ? g_shape.threads : 512;
  l.S = g_shape.stride > 0 ? chunk_stride(g_shape.stride) : 228;  // fastest measured on the H200
  const int P4 = (s.P + 3) & ~3;
  const int base = with_grad ? 2 * P4 : P4;
  l.smem = size_t(chunk_layout(s, l.S, base).total) * sizeof(float);
  // A stride whose buffers exceed the block's shared-memory limit is lowered until they fit.
  while (l.smem > size_t(smem_optin()) && l.S > 36) {
    l.S -= 32;
    l.smem = size_t(chunk_layout(s, l.S, base).total) * sizeof(float);
  }
  if (l.smem > size_t(smem_optin()))
    throw std::invalid_argument("the network is too wide for the CUDA kernels' shared memory");
  const int per_sm = std::max(1, int((228 * 1024) / (l.smem + 1024)));
  const int want = g_shape.blocks > 0 ? g_shape.blocks : sm_count() * per_sm;
  l.blocks = std::max(1, std::min(tasks, want));
  return l;
}

template <class K>
void allow_smem(K kernel, size_t bytes) {
  check(cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, int(bytes)),
        "cudaFuncSetAttribute (shared memory " + std::to_string(bytes) + " bytes)");
}

__device__ inline void load_params(const float* src, float* dst, int P) {
  for (int i = threadIdx.x; i < P; i += blockDim.x) dst[i] = src[i];
}

// ---- kernels ----
template <int D, int ORDER>
__global__ void forward_kernel(NetShape s, const float* params, const float* x, int B, float* out, int S) {
  extern __shared__ float4 smem4[];
  float* sm = reinterpret_cast<float*>(smem4);
  const int P4 = (s.P + 3) & ~3;
  float* W = sm;
  load_params(params, W, s.P);
  Chunk ch = make_chunk(sm, chunk_layout(s, S, P4), S);
  constexpr int C = jet_channels(D, ORDER);
  const int cap = S / C, tasks = (B + cap - 1) / cap;
  __syncthreads();
  for (int t = blockIdx.x; t < tasks; t += gridDim.x) {
    const int begin = t * cap, np = min(cap, B - begin);
    for (int i = threadIdx.x; i < np * D; i += blockDim.x) ch.x[i] = x[size_t(begin) * D + i];
    __syncthreads();
    chunk_forward<D, ORDER>(s, W, np, ch);
    for (int i = threadIdx.x; i < C * np; i += blockDim.x) {
      const int c = i / np, p = i % np;
      out[size_t(c) * B + begin + p] = ch.out[i];
    }
    __syncthreads();
  }
}

template <int D, int ORDER>
__global__ void backward_kernel(NetShape s, const float* params, const float* x, int B, const float* dout,
                                float* partial, int S) {
  extern __shared__ float4 smem4[];
  float* sm = reinterpret_cast<float*>(smem4);
  const int P4 = (s.P + 3) & ~3;
  float* W = sm;
  float* G = sm + P4;
  load_params(params, W, s.P);
  for (int i = threadIdx.x; i < s.P; i += blockDim.x) G[i] = 0.f;
  Chunk ch = make_chunk(sm, chunk_layout(s, S, 2 * P4), S);
  constexpr int C = jet_channels(D, ORDER);
  const int cap = S / C, tasks = (B + cap - 1) / cap;
  __syncthreads();
  for (int t = blockIdx.x; t < tasks; t += gridDim.x) {
    const int begin = t * cap, np = min(cap, B - begin);
    for (int i = threadIdx.x; i < np * D; i += blockDim.x) ch.x[i] = x[size_t(begin) * D + i];
    __syncthreads();
    chunk_forward<D, ORDER>(s, W, np, ch);
    for (int i = threadIdx.x; i < C * np; i += blockDim.x) {
      const int c = i / np, p = i % np;
      ch.dout[i] = dout[size_t(c) * B + begin + p];
    }
    __syncthreads();
    chunk_backward<D, ORDER>(s, W, np, ch, G);
  }
  __syncthreads();
  for (int i = threadIdx.x; i < s.P; i += blockDim.x) partial[size_t(blockIdx.x) * s.P + i] = G[i];
}

template <int D, int ORDER>
__global__ void loss_grad_kernel(NetShape s, const float* params, LossCfg cfg, BatchSrc src, float inv_m,
                                 float inv_k, float* partial, float* sums, int S, int with_grad) {
  extern __shared__ float4 smem4[];
  __shared__ Sums5 sum;
  float* sm = reinterpret_cast<float*>(smem4);
  const int P4 = (s.P + 3) & ~3;
  float* W = sm;
  float* G = with_grad ? sm + P4 : nullptr;
  load_params(params, W, s.P);
  if (G)
    for (int i = threadIdx.x; i < s.P; i += blockDim.x) G[i] = 0.f;
  if (threadIdx.x == 0) sum = Sums5{};
  Chunk ch = make_chunk(sm, chunk_layout(s, S, with_grad ? 2 * P4 : P4), S);
  __syncthreads();
  batch_tasks<D, ORDER>(s, W, cfg, src, inv_m, inv_k, ch, G, &sum, blockIdx.x, gridDim.x);
  if (G)
    for (int i = threadIdx.x; i < s.P; i += blockDim.x) partial[size_t(blockIdx.x) * s.P + i] = G[i];
  if (threadIdx.x == 0) {
    float* o = sums + 5 * blockIdx.x;
    o[0] = sum.z, o[1] = sum.f, o[2] = sum.c, o[3] = sum.s, o[4] = sum.x;
  }
}

// The tensor-core warp path of loss_grad_kernel (cuda/mma_jet.cuh): the batch's data points
// in tiles of 8, then its off-domain points in tiles of 8, tile w, w + W, ... to global warp
// w of W. Each warp keeps its gradient in registers; at the end the warps write it to their
// (now free) buffers and the block sums them in warp order into partial[block].
inline constexpr int kMmaMaxWarps = 16;
// Threads per block the register allocation is bounded for: 16 warps at d = 1 (<= 128
// registers), 8 at d = 2, where shared memory (the per-warp buffers) allows no more.
template <int D>
inline constexpr int kMmaBoundThreads = D == 1 ? 512 : 256;
template <int D, int ORDER>
__global__ void __launch_bounds__(kMmaBoundThreads<D>) mma_loss_grad_kernel(NetShape s, const float* params, LossCfg cfg, BatchSrc src, float inv_m,
                                     float inv_k, float* partial, float* sums, int with_grad) {
  extern __shared__ float4 smem4[];
  __shared__ Sums5 wsum[kMmaMaxWarps];
  constexpr int WF = mma_warp_floats(D, ORDER), MTB = mma_mtiles_max(D, ORDER);
  float* sm = reinterpret_cast<float*>(smem4);
  const int P4 = (s.P + 3) & ~3;
  float* W = sm;
  float4* frag = reinterpret_cast<float4*>(sm + P4);
  float* wbuf = sm + P4 + kMmaFragFloats;
  load_params(params, W, s.P);
  __syncthreads();
  mma_prepare_frags(s, W, frag);
  __syncthreads();
  const int warp = threadIdx.x >> 5, lane = threadIdx.x & 31, nw = blockDim.x >> 5;
  float* mine = wbuf + size_t(warp) * WF;
  float4* slot1 = reinterpret_cast<float4*>(mine);
  float4* slot2 = slot1 + MTB * (kMmaH1 / 8) * 32;
  float4* buf = slot2 + MTB * (kMmaH2 / 8) * 32;
  MmaGrad<D> gr;
  zero(gr);
  Sums5 ls;
  const bool grad = with_grad != 0;
  const int nd = (src.m + 7) / 8, no = src.k > 0 ? (src.k + 7) / 8 : 0;
  for (int tk = blockIdx.x * nw + warp; tk < nd + no; tk += gridDim.x * nw) {
    if (tk < nd) {
      mma_tile<D, ORDER, false, MTB>(s, W, frag, cfg, src, inv_m, inv_k, tk * 8, min(8, src.m - tk * 8), slot1, slot2,
                                     buf, grad, gr, ls);
    } else {
      const int b = (tk - nd) * 8;
      mma_tile<D, 1, true, MTB>(s, W, frag, cfg, src, inv_m, inv_k, b, min(8, src.k - b), slot1, slot2, buf, grad, gr,
                                ls);
    }
  }
  ls.z = sum_over_points(ls.z);
  ls.f = sum_over_points(ls.f);
  ls.c = sum_over_points(ls.c);
  ls.s = sum_over_points(ls.s);
  ls.x = sum_over_points(ls.x);
  if (lane == 0) wsum[warp] = ls;
  if (grad) mma_write_grad(s, gr, mine, lane);
  __syncthreads();
  if (grad)
    for (int i = threadIdx.x; i < s.P; i += blockDim.x) {
      float acc = wbuf[i];
      for (int w = 1; w < nw; ++w) acc += wbuf[size_t(w) * WF + i];
      partial[size_t(blockIdx.x) * s.P + i] = acc;
    }
  if (threadIdx.x == 0) {
    Sums5 t = wsum[0];
    for (int w = 1; w < nw; ++w) t.z += wsum[w].z, t.f += wsum[w].f, t.c += wsum[w].c, t.s += wsum[w].s, t.x += wsum[w].x;
    float* o = sums + 5 * blockIdx.x;
    o[0] = t.z, o[1] = t.f, o[2] = t.c, o[3] = t.s, o[4] = t.x;
  }
}

// One m16n8k8 TF32 MMA of a single warp, fragments by the documented layout (mma_tf32_probe).
__global__ void mma_probe_kernel(const float* A, const float* B, float* Dm, int three) {
  const int lane = threadIdx.x, g = lane >> 2, t = lane & 3;
  const float a0 = A[g * 8 + t], a1 = A[(g + 8) * 8 + t], a2 = A[g * 8 + t + 4], a3 = A[(g + 8) * 8 + t + 4];
  const float b0 = B[t * 8 + g], b1 = B[(t + 4) * 8 + g];
  float4 d = make_float4(0.f, 0.f, 0.f, 0.f);
  if (three) {
    const Tf32x4 a = split4(a0, a1, a2, a3);
    uint32_t b0b, b0s, b1b, b1s;
    split_tf32(b0, b0b, b0s);
    split_tf32(b1, b1b, b1s);
    mma3(d, a, b0b, b1b, b0s, b1s);
  } else {
    const uint32_t a[4] = {__float_as_uint(a0), __float_as_uint(a1), __float_as_uint(a2), __float_as_uint(a3)};
    mma_tf32(d, a, __float_as_uint(b0), __float_as_uint(b1));
  }
  Dm[g * 8 + 2 * t] = d.x;
  Dm[g * 8 + 2 * t + 1] = d.y;
  Dm[(g + 8) * 8 + 2 * t] = d.z;
  Dm[(g + 8) * 8 + 2 * t + 1] = d.w;
}

// dst[i] (+)= sum over blocks b in order of partial[b*P + i].
__global__ void reduce_blocks_kernel(const float* partial, int blocks, int P, float* dst, int accumulate) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= P) return;
  float acc = partial[i];
  for (int b = 1; b < blocks; ++b) acc += partial[size_t(b) * P + i];
  dst[i] = accumulate ? dst[i] + acc : acc;
}

// Per-point loss terms: 4 values per point (z, f, c, x) for data, 1 (s) for off-domain.
template <int D>
__global__ void data_loss_kernel(int B, int order, const float* jet, const float* y, const float* g,
                                 const float* wt, LossCfg cfg, int exact_c, float scale, float* djet,
                                 float* terms) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= B) return;
  const int C = jet_channels(D, order);
  const float wz = float(cfg.wz) * scale, wf = float(cfg.wf) * scale, wc = float(cfg.wc) * scale,
              wx = float(cfg.wx) * scale;
  auto ch = [&](int c) { return jet[size_t(c) * B + p]; };
  float lz = 0, lf = 0, lc = 0, lx = 0;
  const float k = wt ? wt[p] : 1.f;  // the point's weight on its L_Z and L_F residuals
  if (cfg.wz != 0) {
    const float r = ch(0) - y[p];
    lz = k * r * r;
    if (djet) djet[p] += wz * 2.f * k * r;
  }
  if (cfg.wf != 0)
    for (int i = 0; i < D; ++i) {
      const float r = ch(1 + i) - g[p * D + i];
      lf += k * r * r;
      if (djet) djet[size_t(1 + i) * B + p] += wf * 2.f * k * r;
    }
  if (cfg.wc != 0 && exact_c && order >= 3)
    for (int t = 0; t < jet_num_triples(D); ++t) {
      const int c = jet_first(D, 3) + t;
      const float v = ch(c);
      lc += fabsf(v);
      if (djet) djet[size_t(c) * B + p] += wc * float((v > 0) - (v < 0));
    }
  if (cfg.wx != 0 && order >= 2) {
    const int c0 = jet_first(D, 2);
    float lam, da = 1, db = 0, dc = 0;
    if (D == 1) {
      lam = ch(c0);
    } else {
      lam = cpu::min_eigenvalue_2x2<float>(ch(c0), ch(c0 + 1), ch(c0 + 2), &da, &db, &dc);
    }
    if (lam < 0) {
      lx = lam * lam;
      if (djet) {
        const float gl = wx * 2.f * lam;
        djet[size_t(c0) * B + p] += gl * da;
        if (D == 2) {
          djet[size_t(c0 + 1) * B + p] += gl * db;
          djet[size_t(c0 + 2) * B + p] += gl * dc;
        }
      }
    }
  }
  (void)C;
  terms[4 * size_t(p) + 0] = lz;
  terms[4 * size_t(p) + 1] = lf;
  terms[4 * size_t(p) + 2] = lc;
  terms[4 * size_t(p) + 3] = lx;
}

template <int D>
__global__ void strain_loss_kernel(int K, const float* jet, const float* normals, float weight_scale, float* djet,
                                   float* terms) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= K) return;
  float dot = 0;
  for (int i = 0; i < D; ++i) dot += jet[size_t(1 + i) * K + p] * normals[p * D + i];
  float l = 0;
  if (dot < 0) {
    l = dot * dot;
    if (djet)
      for (int i = 0; i < D; ++i) djet[size_t(1 + i) * K + p] += weight_scale * 2.f * dot * normals[p * D + i];
  }
  terms[p] = l;
}

// PyTorch Adam without contraction into FMAs, so that it rounds like cpu::adam_update.
__global__ void adam_kernel(float* p, const float* g, float* m, float* v, int n, float b1, float b2, float one_b1,
                            float one_b2, float eps, float step_size, float bc2_sqrt) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float gi = g[i];
  const float mi = __fadd_rn(__fmul_rn(m[i], b1), __fmul_rn(one_b1, gi));
  const float vi = __fadd_rn(__fmul_rn(v[i], b2), __fmul_rn(__fmul_rn(one_b2, gi), gi));
  m[i] = mi;
  v[i] = vi;
  const float denom = __fadd_rn(__fdiv_rn(__fsqrt_rn(vi), bc2_sqrt), eps);
  p[i] = __fsub_rn(p[i], __fmul_rn(step_size, __fdiv_rn(mi, denom)));
}

LossCfg make_cfg(const cpu::LossOptions& opt, int order) {
  LossCfg c;
  c.wz = opt.w.z, c.wf = opt.w.f, c.wc = opt.w.c, c.ws = opt.w.s, c.wx = opt.w.x;
  c.order = order;
  return c;
}

template <template <int, int> class Sel, class... A>
void dispatch(int d, int order, A&&... a) {
  if (d == 1) {
    if (order == 0) Sel<1, 0>::run(a...);
    else if (order == 1) Sel<1, 1>::run(a...);
    else if (order == 2) Sel<1, 2>::run(a...);
    else Sel<1, 3>::run(a...);
  } else {
    if (order == 0) Sel<2, 0>::run(a...);
    else if (order == 1) Sel<2, 1>::run(a...);
    else if (order == 2) Sel<2, 2>::run(a...);
    else Sel<2, 3>::run(a...);
  }
}

template <int D, int O>
struct FwdSel {
  static void run(const NetShape& s, const float* params, const float* x, int B, float* out) {
    Launch l = pick_launch(s, 1, false);
    const int cap = l.S / jet_channels(D, O);
    l = pick_launch(s, (B + cap - 1) / cap, false);
    allow_smem(forward_kernel<D, O>, l.smem);
    forward_kernel<D, O><<<l.blocks, l.threads, l.smem>>>(s, params, x, B, out, l.S);
    check(cudaGetLastError(), "launch of the jet forward kernel");
  }
};

template <int D, int O>
struct BwdSel {
  static void run(const NetShape& s, const float* params, const float* x, int B, const float* dout,
                  float* dparams, JetWorkspace& ws) {
    Launch l = pick_launch(s, 1, true);
    const int cap = l.S / jet_channels(D, O);
    l = pick_launch(s, (B + cap - 1) / cap, true);
    ws.partial.resize(size_t(l.blocks) * s.P);
    allow_smem(backward_kernel<D, O>, l.smem);
    backward_kernel<D, O><<<l.blocks, l.threads, l.smem>>>(s, params, x, B, dout, ws.partial.data(), l.S);
    check(cudaGetLastError(), "launch of the jet backward kernel");
    reduce_blocks_kernel<<<(s.P + 255) / 256, 256>>>(ws.partial.data(), l.blocks, s.P, dparams, 1);
    check(cudaGetLastError(), "launch of the gradient reduction kernel");
  }
};

bool use_block_path() {
  static const bool env = [] {
    const char* e = std::getenv("YARNHOM_CUDA_PATH");
    return e != nullptr && std::strcmp(e, "block") == 0;
  }();
  return env || g_shape.block_path;
}

// The warp path's launch: as many warps per block as shared memory (the per-warp buffers) and
// registers allow, up to 16, and as many blocks as fit on the GPU at once (at most one warp
// per tile). Returns false, launching nothing, where not even one warp fits (a GPU with less
// shared memory per block): the block path runs instead.
template <int D, int O>
bool launch_mma_loss_grad(const NetShape& s, const float* params, const LossCfg& cfg, const BatchSrc& src,
                          float inv_m, float inv_k, float* grad, JetWorkspace& ws, int* blocks_out) {
  auto kernel = mma_loss_grad_kernel<D, O>;
  constexpr int WF = mma_warp_floats(D, O);
  if (s.P > WF) return false;  // the warps' buffers hold the gradient at the end
  const int P4 = (s.P + 3) & ~3;
  const size_t fixed = size_t(P4 + kMmaFragFloats) * sizeof(float), per_warp = size_t(WF) * sizeof(float);
  cudaFuncAttributes attr{};
  check(cudaFuncGetAttributes(&attr, kernel), "cudaFuncGetAttributes");
  const long long avail = (long long)smem_optin() - (long long)attr.sharedSizeBytes - (long long)fixed;
  int nw = std::min<int>(kMmaMaxWarps, attr.maxThreadsPerBlock / 32);
  nw = std::min<long long>(nw, avail > 0 ? avail / (long long)per_warp : 0);
  if (nw < 1) return false;
  if (g_shape.threads > 0) nw = std::max(1, std::min(nw, g_shape.threads / 32));
  const size_t smem = fixed + nw * per_warp;
  allow_smem(kernel, smem);
  int per_sm = 0;
  check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, nw * 32, smem),
        "cudaOccupancyMaxActiveBlocksPerMultiprocessor");
  const int tiles = (src.m + 7) / 8 + (src.k > 0 ? (src.k + 7) / 8 : 0);
  const int want = g_shape.blocks > 0 ? g_shape.blocks : sm_count() * std::max(1, per_sm);
  const int blocks = std::max(1, std::min(want, (tiles + nw - 1) / nw));
  if (grad) ws.partial.resize(size_t(blocks) * s.P);
  ws.sums.resize(size_t(blocks) * 5);
  kernel<<<blocks, nw * 32, smem>>>(s, params, cfg, src, inv_m, inv_k, grad ? ws.partial.data() : nullptr,
                                    ws.sums.data(), grad ? 1 : 0);
  check(cudaGetLastError(), "launch of the tensor-core loss kernel");
  if (grad) {
    reduce_blocks_kernel<<<(s.P + 255) / 256, 256>>>(ws.partial.data(), blocks, s.P, grad, 0);
    check(cudaGetLastError(), "launch of the gradient reduction kernel");
  }
  *blocks_out = blocks;
  return true;
}

template <int D, int O>
struct LossSel {
  static void run(const NetShape& s, const float* params, const LossCfg& cfg, const BatchSrc& src, float inv_m,
                  float inv_k, float* grad, JetWorkspace& ws, int* blocks_out) {
    if (mma_path_fits(s) && !use_block_path() &&
        launch_mma_loss_grad<D, O>(s, params, cfg, src, inv_m, inv_k, grad, ws, blocks_out))
      return;
    Launch l = pick_launch(s, 1, grad != nullptr);
    const TaskPlan tp = plan_tasks<D, O>(l.S, src.m, src.k);
    l = pick_launch(s, std::max(1, tp.tasks()), grad != nullptr);
    if (grad) ws.partial.resize(size_t(l.blocks) * s.P);
    ws.sums.resize(size_t(l.blocks) * 5);
    allow_smem(loss_grad_kernel<D, O>, l.smem);
    loss_grad_kernel<D, O><<<l.blocks, l.threads, l.smem>>>(s, params, cfg, src, inv_m, inv_k,
                                                            grad ? ws.partial.data() : nullptr, ws.sums.data(),
                                                            l.S, grad ? 1 : 0);
    check(cudaGetLastError(), "launch of the fused loss kernel");
    if (grad) {
      reduce_blocks_kernel<<<(s.P + 255) / 256, 256>>>(ws.partial.data(), l.blocks, s.P, grad, 0);
      check(cudaGetLastError(), "launch of the gradient reduction kernel");
    }
    *blocks_out = l.blocks;
  }
};

}  // namespace

void set_launch_shape(const LaunchShape& s) { g_shape = s; }

void mlp_jet_forward(const NetworkDesc& desc, const float* params, const float* x, int batch, int order,
                     float* out, JetWorkspace& ws) {
  (void)ws;
  const NetShape s = make_shape(desc);
  if (batch <= 0) return;
  dispatch<FwdSel>(s.d, order, s, params, x, batch, out);
}

void mlp_jet_backward(const NetworkDesc& desc, const float* params, const float* x, int batch, int order,
                      const float* dout, float* dparams, JetWorkspace& ws) {
  const NetShape s = make_shape(desc);
  if (batch <= 0) return;
  dispatch<BwdSel>(s.d, order, s, params, x, batch, dout, dparams, ws);
}

cpu::LossSums<float> data_losses(int d, int B, int order, const float* jet, const float* y, const float* g,
                                 const float* wt, const LossWeights& w, bool exact_c, float scale,
                                 float* djet) {
  cpu::LossSums<float> sum;
  if (B <= 0) return sum;
  DeviceVec<float> terms(size_t(B) * 4);
  cpu::LossOptions o;
  o.w = w;
  const LossCfg cfg = make_cfg(o, order);
  const int T = 128, G = (B + T - 1) / T;
  if (d == 1)
    data_loss_kernel<1><<<G, T>>>(B, order, jet, y, g, wt, cfg, exact_c, scale, djet, terms.data());
  else
    data_loss_kernel<2><<<G, T>>>(B, order, jet, y, g, wt, cfg, exact_c, scale, djet, terms.data());
  check(cudaGetLastError(), "launch of the data loss kernel");
  const std::vector<float> h = terms.download();
  for (int p = 0; p < B; ++p) {
    sum.z += h[4 * p + 0];
    sum.f += h[4 * p + 1];
    sum.c += h[4 * p + 2];
    sum.x += h[4 * p + 3];
  }
  return sum;
}

float strain_concentration_loss(int d, int K, int order, const float* jet, const float* normals,
                                float weight_scale, float* djet) {
  (void)order;
  if (K <= 0) return 0.f;
  DeviceVec<float> terms(K);
  const int T = 128, G = (K + T - 1) / T;
  if (d == 1)
    strain_loss_kernel<1><<<G, T>>>(K, jet, normals, weight_scale, djet, terms.data());
  else
    strain_loss_kernel<2><<<G, T>>>(K, jet, normals, weight_scale, djet, terms.data());
  check(cudaGetLastError(), "launch of the strain-concentration loss kernel");
  const std::vector<float> h = terms.download();
  float sum = 0;
  for (int p = 0; p < K; ++p) sum += h[p];
  return sum;
}

void adam_update(float* p, const float* g, float* m, float* v, int n, const cpu::AdamParams& a, int64_t step) {
  if (n <= 0) return;
  const double bc1 = 1.0 - std::pow(a.beta1, double(step));
  const double bc2 = 1.0 - std::pow(a.beta2, double(step));
  const int T = 256;
  adam_kernel<<<(n + T - 1) / T, T>>>(p, g, m, v, n, float(a.beta1), float(a.beta2), float(1.0 - a.beta1),
                                      float(1.0 - a.beta2), float(a.eps), float(a.lr / bc1),
                                      float(std::sqrt(bc2)));
  check(cudaGetLastError(), "launch of the Adam kernel");
}

namespace {
struct Prepared {
  NetShape s;
  LossCfg cfg;
  BatchSrc src;
  float inv_m, inv_k;
  int order;
};
Prepared prepare(const NetworkDesc& desc, const cpu::LossBatch<float>& batch, const cpu::LossOptions& opt) {
  if (opt.stencil_c && opt.w.c != 0)
    throw std::invalid_argument("the CUDA backend computes L_C exactly; the stencil option is CPU-only");
  if (batch.wt)
    throw std::invalid_argument("the fused CUDA loss has no per-point weights (the full-batch polish that uses them runs on the CPU)");
  Prepared q;
  q.s = make_shape(desc);
  q.order = cpu::data_jet_order(opt);
  q.cfg = make_cfg(opt, q.order);
  q.src.m = batch.m, q.src.x = batch.x, q.src.y = batch.y, q.src.g = batch.g;
  q.src.k = (batch.k > 0 && opt.w.s != 0) ? batch.k : 0;
  q.src.xo = batch.xo, q.src.no = batch.no;
  q.inv_m = batch.m > 0 ? 1.f / float(batch.m) : 0.f;
  q.inv_k = batch.k > 0 ? 1.f / float(batch.k) : 0.f;
  return q;
}
}  // namespace

void mlp_loss_grad_launch(const NetworkDesc& desc, const float* params, const cpu::LossBatch<float>& batch,
                          const cpu::LossOptions& opt, float* grad, JetWorkspace& ws) {
  const Prepared q = prepare(desc, batch, opt);
  if (q.src.m + q.src.k == 0) return;
  int blocks = 0;
  dispatch<LossSel>(q.s.d, q.order, q.s, params, q.cfg, q.src, q.inv_m, q.inv_k, grad, ws, &blocks);
}

std::vector<float> mma_tf32_probe(const std::vector<float>& a, const std::vector<float>& b, bool three) {
  if (a.size() != 128 || b.size() != 64) throw std::invalid_argument("mma_tf32_probe: A is 16x8, B 8x8");
  DeviceVec<float> da(a), db(b), dd(128);
  mma_probe_kernel<<<1, 32>>>(da.data(), db.data(), dd.data(), three ? 1 : 0);
  check(cudaGetLastError(), "launch of the MMA probe kernel");
  return dd.download();
}

EventTimer::EventTimer() {
  cudaEvent_t a, b;
  check(cudaEventCreate(&a), "cudaEventCreate");
  check(cudaEventCreate(&b), "cudaEventCreate");
  a_ = a, b_ = b;
}
EventTimer::~EventTimer() {
  cudaEventDestroy(static_cast<cudaEvent_t>(a_));
  cudaEventDestroy(static_cast<cudaEvent_t>(b_));
}
void EventTimer::start() { check(cudaEventRecord(static_cast<cudaEvent_t>(a_)), "cudaEventRecord"); }
double EventTimer::stop_ms() {
  check(cudaEventRecord(static_cast<cudaEvent_t>(b_)), "cudaEventRecord");
  check(cudaEventSynchronize(static_cast<cudaEvent_t>(b_)), "cudaEventSynchronize");
  float ms = 0;
  check(cudaEventElapsedTime(&ms, static_cast<cudaEvent_t>(a_), static_cast<cudaEvent_t>(b_)), "cudaEventElapsedTime");
  return ms;
}

cpu::LossValues mlp_loss_grad(const NetworkDesc& desc, const float* params, const cpu::LossBatch<float>& batch,
                              const cpu::LossOptions& opt, float* grad, JetWorkspace& ws) {
  const Prepared q = prepare(desc, batch, opt);
  const float inv_m = q.inv_m, inv_k = q.inv_k;
  if (q.src.m + q.src.k == 0) {
    if (grad) check(cudaMemset(grad, 0, sizeof(float) * q.s.P), "cudaMemset");
    return {};
  }
  int blocks = 0;
  dispatch<LossSel>(q.s.d, q.order, q.s, params, q.cfg, q.src, inv_m, inv_k, grad, ws, &blocks);
  const std::vector<float> h = ws.sums.download();
  cpu::LossSums<float> tot;
  for (int b = 0; b < blocks; ++b) {
    tot.z += h[5 * b + 0];
    tot.f += h[5 * b + 1];
    tot.c += h[5 * b + 2];
    tot.s += h[5 * b + 3];
    tot.x += h[5 * b + 4];
  }
  cpu::LossValues v;
  v.z = double(tot.z) * double(inv_m);
  v.f = double(tot.f) * double(inv_m);
  v.c = double(tot.c) * double(inv_m);
  v.x = double(tot.x) * double(inv_m);
  v.s = double(tot.s) * double(inv_k);
  v.total = opt.w.z * v.z + opt.w.f * v.f + opt.w.c * v.c + opt.w.s * v.s + opt.w.x * v.x;
  return v;
}

}  // namespace yarnhom::cuda
