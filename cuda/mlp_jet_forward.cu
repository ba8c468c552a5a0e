// Twin of cpu::mlp_jet_forward (cpu/mlp_jet_forward.cpp): the jet forward pass of a batch, a
// chunk of points per block at a time in shared memory (cuda/chunk_jet.cuh).
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
__global__ void forward_kernel(NetShape s, const float* params, const float* x, int B, float* out, int S) {
  extern __shared__ float4 smem4[];
  float* sm = reinterpret_cast<float*>(smem4);
  const int P4 = (s.P + 3) & ~3;
  float* W = sm;
  load_params(params, W, s.P);
  Chunk ch = make_chunk(sm, chunk_layout(s, S, P4), S);
  constexpr int C = jet_channels(D, ORDER);
  for_each_chunk<D, ORDER>(s, W, x, B, ch, [&](int begin, int np) {
    for (int i = threadIdx.x; i < C * np; i += blockDim.x) {
      const int c = i / np, p = i % np;
      out[size_t(c) * B + begin + p] = ch.out[i];
    }
    __syncthreads();
  });
}

template <int D, int O>
struct FwdSel {
  static void run(const NetShape& s, const float* params, const float* x, int B, float* out) {
    const Launch l = pick_chunk_launch(s, B, jet_channels(D, O), false);
    allow_smem(forward_kernel<D, O>, l.smem);
    forward_kernel<D, O><<<l.blocks, l.threads, l.smem>>>(s, params, x, B, out, l.S);
    check(cudaGetLastError(), "launch of the jet forward kernel");
  }
};

}  // namespace

void mlp_jet_forward(const NetworkDesc& desc, const float* params, const float* x, int batch, int order,
                     float* out, JetWorkspace& ws) {
  (void)ws;
  const NetShape s = make_shape(desc);
  if (batch <= 0) return;
  dispatch<FwdSel>(s.d, order, s, params, x, batch, out);
}

}  // namespace yarnhom::cuda
