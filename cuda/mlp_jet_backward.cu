// Twin of cpu::mlp_jet_backward (cpu/mlp_jet_backward.cpp): every block recomputes the jet
// forward pass of its chunks of points in shared memory, then runs their reverse pass
// (cuda/chunk_jet.cuh), adding the chunks' gradients in chunk order; the blocks' partial
// gradients are then summed in block order into dparams.
#include <cuda_runtime.h>

#include <cstddef>

#include "cuda/api.hpp"
#include "cuda/check.cuh"
#include "cuda/jet_block.cuh"
#include "cuda/launch.cuh"

namespace yarnhom::cuda {

using namespace detail;

namespace {

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
  for_each_chunk<D, ORDER>(s, W, x, B, ch, [&](int begin, int np) {
    for (int i = threadIdx.x; i < C * np; i += blockDim.x) {
      const int c = i / np, p = i % np;
      ch.dout[i] = dout[size_t(c) * B + begin + p];
    }
    __syncthreads();
    chunk_backward<D, ORDER>(s, W, np, ch, G);
  });
  __syncthreads();
  for (int i = threadIdx.x; i < s.P; i += blockDim.x) partial[size_t(blockIdx.x) * s.P + i] = G[i];
}

template <int D, int O>
struct BwdSel {
  static void run(const NetShape& s, const float* params, const float* x, int B, const float* dout,
                  float* dparams, JetWorkspace& ws) {
    const Launch l = pick_chunk_launch(s, B, jet_channels(D, O), true);
    ws.partial.resize(size_t(l.blocks) * s.P);
    allow_smem(backward_kernel<D, O>, l.smem);
    backward_kernel<D, O><<<l.blocks, l.threads, l.smem>>>(s, params, x, B, dout, ws.partial.data(), l.S);
    check(cudaGetLastError(), "launch of the jet backward kernel");
    reduce_blocks(ws.partial.data(), l.blocks, s.P, dparams, true);
  }
};

}  // namespace

void mlp_jet_backward(const NetworkDesc& desc, const float* params, const float* x, int batch, int order,
                      const float* dout, float* dparams, JetWorkspace& ws) {
  const NetShape s = make_shape(desc);
  if (batch <= 0) return;
  dispatch<BwdSel>(s.d, order, s, params, x, batch, dout, dparams, ws);
}

}  // namespace yarnhom::cuda
