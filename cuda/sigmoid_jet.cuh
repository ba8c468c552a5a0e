#pragma once
// The sigmoid jet map to third order of one neuron at one point and its reverse mode (twins of
// cpu/sigmoid_jet.hpp), and the same over a layer of a chunk (a thread per neuron and point).
#include "core/jet_layout.hpp"

namespace yarnhom::cuda::detail {

#ifdef __CUDACC__

__device__ inline float sigmoidf_(float z) { return 1.f / (1.f + expf(-z)); }

// Sigmoid jet forward of one neuron at one point (cpu/sigmoid_jet.hpp): z[c*st] -> a[c*st].
template <int D, int ORDER>
__device__ inline void sigmoid_jet_point(const float* zp, float* ap, int st) {
  constexpr int C = jet_channels(D, ORDER);
  float z[C];
#pragma unroll
  for (int c = 0; c < C; ++c) z[c] = zp[c * st];
  const float s0 = sigmoidf_(z[0]);
  const float s1 = s0 * (1.f - s0);
  const float s2 = s1 * (1.f - 2.f * s0);
  const float s3 = s1 * (1.f - 6.f * s0 + 6.f * s0 * s0);
  ap[0] = s0;
  if constexpr (ORDER >= 1) {
#pragma unroll
    for (int i = 0; i < D; ++i) ap[(1 + i) * st] = s1 * z[1 + i];
  }
  if constexpr (ORDER >= 2) {
#pragma unroll
    for (int q = 0; q < jet_num_pairs(D); ++q) {
      const JetPair e = jet_pair(D, q);
      const int c = jet_first(D, 2) + q;
      ap[c * st] = s2 * z[1 + e.i] * z[1 + e.j] + s1 * z[c];
    }
  }
  if constexpr (ORDER >= 3) {
#pragma unroll
    for (int t = 0; t < jet_num_triples(D); ++t) {
      const JetTriple e = jet_triple(D, t);
      const int c = jet_first(D, 3) + t;
      const float zi = z[1 + e.i], zj = z[1 + e.j], zk = z[1 + e.k];
      const float zij = z[jet_ch2(D, e.i, e.j)], zik = z[jet_ch2(D, e.i, e.k)], zjk = z[jet_ch2(D, e.j, e.k)];
      ap[c * st] = s3 * zi * zj * zk + s2 * (zij * zk + zik * zj + zjk * zi) + s1 * z[c];
    }
  }
}

// Reverse mode of sigmoid_jet_point (cpu/sigmoid_jet.hpp, sigmoid_jet_backward_impl): from
// abar[c*st] and the forward's z and s0 = a channel 0, writes zbar[c*st]. In place is allowed
// (zbar == abar).
template <int D, int ORDER>
__device__ inline void sigmoid_jet_point_backward(const float* zp, float s0, const float* abp, float* zbp, int st) {
  constexpr int C = jet_channels(D, ORDER);
  float z[C], ab[C], zb[C];
#pragma unroll
  for (int c = 0; c < C; ++c) {
    z[c] = zp[c * st];
    ab[c] = abp[c * st];
  }
  const float s1 = s0 * (1.f - s0);
  const float s2 = s1 * (1.f - 2.f * s0);
  const float s3 = s1 * (1.f - 6.f * s0 + 6.f * s0 * s0);
  const float s4 = s1 * (1.f - 2.f * s0) * (1.f - 12.f * s0 + 12.f * s0 * s0);
#pragma unroll
  for (int c = 0; c < C; ++c) zb[c] = ab[c] * s1;
  if constexpr (ORDER >= 1) {
#pragma unroll
    for (int i = 0; i < D; ++i) zb[0] += ab[1 + i] * s2 * z[1 + i];
  }
  if constexpr (ORDER >= 2) {
#pragma unroll
    for (int q = 0; q < jet_num_pairs(D); ++q) {
      const JetPair e = jet_pair(D, q);
      const int c = jet_first(D, 2) + q;
      const float g = ab[c];
      zb[0] += g * (s3 * z[1 + e.i] * z[1 + e.j] + s2 * z[c]);
      zb[1 + e.i] += g * s2 * z[1 + e.j];
      zb[1 + e.j] += g * s2 * z[1 + e.i];
    }
  }
  if constexpr (ORDER >= 3) {
#pragma unroll
    for (int t = 0; t < jet_num_triples(D); ++t) {
      const JetTriple e = jet_triple(D, t);
      const int c = jet_first(D, 3) + t;
      const int cij = jet_ch2(D, e.i, e.j), cik = jet_ch2(D, e.i, e.k), cjk = jet_ch2(D, e.j, e.k);
      const float g = ab[c];
      const float zi = z[1 + e.i], zj = z[1 + e.j], zk = z[1 + e.k];
      const float zij = z[cij], zik = z[cik], zjk = z[cjk];
      zb[0] += g * (s4 * zi * zj * zk + s3 * (zij * zk + zik * zj + zjk * zi) + s2 * z[c]);
      zb[1 + e.i] += g * (s3 * zj * zk + s2 * zjk);
      zb[1 + e.j] += g * (s3 * zi * zk + s2 * zik);
      zb[1 + e.k] += g * (s3 * zi * zj + s2 * zij);
      zb[cij] += g * s2 * zk;
      zb[cik] += g * s2 * zj;
      zb[cjk] += g * s2 * zi;
    }
  }
#pragma unroll
  for (int c = 0; c < C; ++c) zbp[c * st] = zb[c];
}

template <int D, int ORDER>
__device__ inline void sigmoid_layer_fwd(const float* Z, float* A, int n, int np, int S) {
  for (int t = threadIdx.x; t < n * np; t += blockDim.x) {
    const int r = t / np, p = t % np;
    sigmoid_jet_point<D, ORDER>(Z + r * S + p, A + r * S + p, np);
  }
}
template <int D, int ORDER>
__device__ inline void sigmoid_layer_bwd(const float* Z, const float* A, float* Bar, int n, int np, int S) {
  for (int t = threadIdx.x; t < n * np; t += blockDim.x) {
    const int r = t / np, p = t % np;
    sigmoid_jet_point_backward<D, ORDER>(Z + r * S + p, A[r * S + p], Bar + r * S + p, Bar + r * S + p, np);
  }
}

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
