#pragma once
// How the multi-block twins launch (cuda/launch.cu): the launch shape the benchmarks set, the
// device's multiprocessor count and shared-memory opt-in, the choice of stride and blocks of a
// chunked kernel, the dispatch on (d, order) to compiled kernels, the sum of the blocks'
// partial gradients in block order; and the device-side pieces every twin kernel starts with
// (the weights in shared memory, the loop over a batch's chunks).
#include <cuda_runtime.h>

#include <cstddef>
#include <string>

#include "cuda/api.hpp"
#include "cuda/check.cuh"
#include "cuda/chunk_jet.cuh"
#include "cuda/jet_shape.cuh"

namespace yarnhom::cuda::detail {

// The shape set by set_launch_shape (0 = the defaults).
const LaunchShape& launch_shape();
// The device's multiprocessors and its opt-in shared memory per block (bytes), read once.
int sm_count();
int smem_optin();

struct Launch {
  int threads, S, blocks;
  size_t smem;  // bytes
};

// Shared memory of a multi-block twin: params (and gradient) then the chunk buffers. The
// stride is the launch shape's, lowered until the buffers fit; at most `tasks` blocks.
Launch pick_launch(const NetShape& s, int tasks, bool with_grad);

// The launch of a twin that cuts B points into chunks of S / C points: the stride first, then
// as many blocks as there are chunks (at most).
inline Launch pick_chunk_launch(const NetShape& s, int B, int C, bool with_grad) {
  Launch l = pick_launch(s, 1, with_grad);
  const int cap = l.S / C;
  return pick_launch(s, (B + cap - 1) / cap, with_grad);
}

template <class K>
void allow_smem(K kernel, size_t bytes) {
  check(cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, int(bytes)),
        "cudaFuncSetAttribute (shared memory " + std::to_string(bytes) + " bytes)");
}

// dst[i] (+)= sum over blocks b in order of partial[b*P + i] (a thread per parameter).
void reduce_blocks(const float* partial, int blocks, int P, float* dst, bool accumulate);

// Loss configuration of the kernels from the CPU's options at data-jet order `order`.
inline LossCfg make_cfg(const cpu::LossOptions& opt, int order) {
  LossCfg c;
  c.wz = opt.w.z, c.wf = opt.w.f, c.wc = opt.w.c, c.ws = opt.w.s, c.wx = opt.w.x;
  c.order = order;
  return c;
}

// Sel<D, ORDER>::run(a...) for the network's input dimension d (1 or 2) and the jet order.
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

// ---- device side ----

__device__ inline void load_params(const float* src, float* dst, int P) {
  for (int i = threadIdx.x; i < P; i += blockDim.x) dst[i] = src[i];
}

// The chunks blockIdx.x, + gridDim.x, ... of a batch of B points x [B, D], ch.S / C points each:
// loads a chunk's inputs, runs its jet forward pass, then after(begin, np) (which ends with a
// barrier or a block-wide pass that does). Starts with a barrier (the caller's shared setup).
template <int D, int ORDER, class After>
__device__ __forceinline__ void for_each_chunk(const NetShape& s, const float* W, const float* x, int B, Chunk& ch,
                                               After&& after) {
  constexpr int C = jet_channels(D, ORDER);
  const int cap = ch.S / C, tasks = (B + cap - 1) / cap;
  __syncthreads();
  for (int t = blockIdx.x; t < tasks; t += gridDim.x) {
    const int begin = t * cap, np = min(cap, B - begin);
    for (int i = threadIdx.x; i < np * D; i += blockDim.x) ch.x[i] = x[size_t(begin) * D + i];
    __syncthreads();
    chunk_forward<D, ORDER>(s, W, np, ch);
    after(begin, np);
  }
}

}  // namespace yarnhom::cuda::detail
