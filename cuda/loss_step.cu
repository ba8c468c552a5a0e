// Twin of cpu::mlp_loss_grad (cpu/loss_step.cpp): the fused forward jets, losses and reverse
// pass of one batch, on one of two paths with the same math:
//   the block path (loss_grad_kernel): the batch's tasks (chunks of points) spread over blocks,
//     each task run by a whole block in shared memory (cuda/batch_tasks.cuh);
//   the tensor-core warp path (mma_loss_grad_kernel, the paper's Net-3 only): tiles of 8
//     points spread over warps, the hidden-to-hidden products as 3xTF32 MMAs (cuda/mma_jet.cuh).
// Either way each block writes its partial gradient and loss sums; the gradient is summed in
// block order on the device (reduce_blocks), the loss sums in block order on the host.
#include <cuda_runtime.h>

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "cpu/loss_types.hpp"
#include "cuda/api.hpp"
#include "cuda/check.cuh"
#include "cuda/jet_block.cuh"
#include "cuda/launch.cuh"
#include "cuda/mma_jet.cuh"

namespace yarnhom::cuda {

using namespace detail;

namespace {

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

bool use_block_path() {
  static const bool env = [] {
    const char* e = std::getenv("YARNHOM_CUDA_PATH");
    return e != nullptr && std::strcmp(e, "block") == 0;
  }();
  return env || launch_shape().block_path;
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
  const LaunchShape& shape = launch_shape();
  const int P4 = (s.P + 3) & ~3;
  const size_t fixed = size_t(P4 + kMmaFragFloats) * sizeof(float), per_warp = size_t(WF) * sizeof(float);
  cudaFuncAttributes attr{};
  check(cudaFuncGetAttributes(&attr, kernel), "cudaFuncGetAttributes");
  const long long avail = (long long)smem_optin() - (long long)attr.sharedSizeBytes - (long long)fixed;
  int nw = std::min<int>(kMmaMaxWarps, attr.maxThreadsPerBlock / 32);
  nw = std::min<long long>(nw, avail > 0 ? avail / (long long)per_warp : 0);
  if (nw < 1) return false;
  if (shape.threads > 0) nw = std::max(1, std::min(nw, shape.threads / 32));
  const size_t smem = fixed + nw * per_warp;
  allow_smem(kernel, smem);
  int per_sm = 0;
  check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, nw * 32, smem),
        "cudaOccupancyMaxActiveBlocksPerMultiprocessor");
  const int tiles = (src.m + 7) / 8 + (src.k > 0 ? (src.k + 7) / 8 : 0);
  const int want = shape.blocks > 0 ? shape.blocks : sm_count() * std::max(1, per_sm);
  const int blocks = std::max(1, std::min(want, (tiles + nw - 1) / nw));
  if (grad) ws.partial.resize(size_t(blocks) * s.P);
  ws.sums.resize(size_t(blocks) * 5);
  kernel<<<blocks, nw * 32, smem>>>(s, params, cfg, src, inv_m, inv_k, grad ? ws.partial.data() : nullptr,
                                    ws.sums.data(), grad ? 1 : 0);
  check(cudaGetLastError(), "launch of the tensor-core loss kernel");
  if (grad) reduce_blocks(ws.partial.data(), blocks, s.P, grad, false);
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
    if (grad) reduce_blocks(ws.partial.data(), l.blocks, s.P, grad, false);
    *blocks_out = l.blocks;
  }
};

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
