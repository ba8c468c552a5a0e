#pragma once
// The jet forward pass and the reverse pass of a chunk of points in shared memory, layer by
// layer (twins of cpu::mlp_jet_forward and cpu::mlp_jet_backward on one chunk).
#include "core/jet_layout.hpp"
#include "cuda/block_products.cuh"
#include "cuda/jet_shape.cuh"
#include "cuda/sigmoid_jet.cuh"

namespace yarnhom::cuda::detail {

#ifdef __CUDACC__

// The jet forward pass of a chunk: inputs ch.x [np, D], output jet in ch.out[c*np + p].
// Twin of cpu::mlp_jet_forward on one chunk.
template <int D, int ORDER>
__device__ void chunk_forward(const NetShape& s, const float* W, int np, Chunk& ch) {
  constexpr int C = jet_channels(D, ORDER);
  const int N = C * np, S = ch.S;
  // Layer 0: the input jet is (x, e_i, 0, 0): z = W x + b, z_i = W[:, i], zero above.
  {
    const int n = s.out[0];
    const float* W0 = W + s.woff[0];
    const float* b0 = W + s.boff[0];
    float* Z = ch.z + s.hoff[0] * S;
    for (int t = threadIdx.x; t < n * N; t += blockDim.x) {
      const int r = t / N, col = t % N, c = col / np, p = col % np;
      float v;
      if (c == 0) {
        float acc = 0.f;
#pragma unroll
        for (int i = 0; i < D; ++i) acc = fmaf(W0[r * D + i], ch.x[p * D + i], acc);
        v = acc + b0[r];
      } else {
        v = c <= D ? W0[r * D + (c - 1)] : 0.f;
      }
      Z[r * S + col] = v;
    }
  }
  __syncthreads();
  for (int k = 1; k < s.L; ++k) {
    const float* Zp = ch.z + s.hoff[k - 1] * S;
    float* Ap = ch.a + s.hoff[k - 1] * S;
    sigmoid_layer_fwd<D, ORDER>(Zp, Ap, s.out[k - 1], np, S);
    __syncthreads();
    float* Zk = k == s.L - 1 ? ch.out : ch.z + s.hoff[k] * S;
    block_gemm(W + s.woff[k], s.in[k], 1, W + s.boff[k], np, s.out[k], s.in[k], Ap, Zk, S, N);
    __syncthreads();
  }
}

// The reverse pass of a chunk (twin of cpu::mlp_jet_backward on one chunk): from ch.dout, the
// chunk's parameter gradient, added by its owning thread into G (shared or global; G[i] +=
// chunk's dL/dp_i). Needs the buffers of chunk_forward on the same chunk.
template <int D, int ORDER>
__device__ void chunk_backward(const NetShape& s, const float* W, int np, Chunk& ch, float* G) {
  constexpr int C = jet_channels(D, ORDER);
  const int N = C * np, S = ch.S;
  const float* zbar = ch.dout;  // adjoint of layer k's pre-activation jet, [out_k, S]
  float* bufs[2] = {ch.bufA, ch.bufB};
  int which = 0;
  for (int k = s.L - 1; k >= 1; --k) {
    const int n = s.out[k], m = s.in[k];
    const float* Aprev = ch.a + s.hoff[k - 1] * S;
    // Phase 1: the weight gradient's partial tiles, the bias gradient, and
    // abar_{k-1}[j][col] = sum_r W[r][j] zbar[r][col] (independent: no barrier between).
    const DwPlan dp = dw_plan(n, m, N);
    dw_partials(dp, zbar, Aprev, n, m, N, S, ch.dwp);
    for (int r = threadIdx.x; r < n; r += blockDim.x) G[s.boff[k] + r] += sum_cols(zbar + r * S, np);
    float* abar = bufs[which];
    which ^= 1;
    block_gemm(W + s.woff[k], 1, m, nullptr, 0, m, n, zbar, abar, S, N);
    __syncthreads();
    // Phase 2: the weight gradient summed over slices into G, and zbar_{k-1} = the sigmoid
    // jet's reverse (in place).
    dw_reduce(dp, ch.dwp, n, m, G + s.woff[k]);
    sigmoid_layer_bwd<D, ORDER>(ch.z + s.hoff[k - 1] * S, Aprev, abar, m, np, S);
    __syncthreads();
    zbar = abar;
  }
  // Layer 0: dW0[r][i] = sum_p zbar[r][p] x[p][i] + sum_p zbar[r][(1+i) np + p]; db0 = sum_p zbar[r][p].
  const int n = s.out[0];
  for (int t = threadIdx.x; t < n * (D + 1); t += blockDim.x) {
    const int r = t / (D + 1), i = t % (D + 1);
    const float* zr = zbar + r * S;
    if (i < D) {
      float a = 0.f;
      for (int p = 0; p < np; ++p) a = fmaf(zr[p], ch.x[p * D + i], a);
      if (ORDER >= 1) a += sum_cols(zr + (1 + i) * np, np);
      G[s.woff[0] + r * D + i] += a;
    } else {
      G[s.boff[0] + r] += sum_cols(zr, np);
    }
  }
  __syncthreads();
}

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
