#pragma once
// The losses on the output jet and their adjoints: of one data point (shared by the block path
// and the tensor-core warp path), of a chunk of data points, and of a chunk of off-domain
// points (twins of cpu::data_losses and cpu::strain_concentration_loss).
#include "core/jet_layout.hpp"
#include "cuda/block_products.cuh"
#include "cuda/jet_shape.cuh"

namespace yarnhom::cuda::detail {

#ifdef __CUDACC__

// The data losses of one point (twin of cpu::data_losses on one point): jet[C] -> the loss
// terms and, with the weights already multiplied by the batch scale (wz..wx), the adjoint of
// every channel in adj[C] (zeroed here). Shared by the block path (chunk_data_losses) and the
// tensor-core warp path (cuda/mma_jet.cuh).
struct PointLoss {
  float z = 0, f = 0, c = 0, x = 0;
};
template <int D, int ORDER>
__device__ inline PointLoss point_data_loss(const LossCfg& cfg, float wz, float wf, float wc, float wx,
                                            const float* jet, float y, const float* g, float* adj) {
  constexpr int C = jet_channels(D, ORDER);
  PointLoss l;
#pragma unroll
  for (int c = 0; c < C; ++c) adj[c] = 0.f;
  if (cfg.wz != 0) {
    const float r = jet[0] - y;
    l.z = r * r;
    adj[0] += wz * 2.f * r;
  }
  if constexpr (ORDER >= 1) {
    if (cfg.wf != 0) {
#pragma unroll
      for (int i = 0; i < D; ++i) {
        const float r = jet[1 + i] - g[i];
        l.f += r * r;
        adj[1 + i] += wf * 2.f * r;
      }
    }
  }
  if constexpr (ORDER >= 3) {
    if (cfg.wc != 0) {
#pragma unroll
      for (int t = 0; t < jet_num_triples(D); ++t) {
        const int c = jet_first(D, 3) + t;
        const float v = jet[c];
        l.c += fabsf(v);
        adj[c] += wc * float((v > 0) - (v < 0));
      }
    }
  }
  if constexpr (ORDER >= 2) {
    if (cfg.wx != 0) {
      const int c0 = jet_first(D, 2);
      float lam, da = 1, db = 0, dc = 0;
      if (D == 1) {
        lam = jet[c0];
      } else {
        // cpu::min_eigenvalue_2x2
        const float a = jet[c0], b = jet[c0 + 1], c = jet[c0 + 2];
        const float h = (a - c) / 2.f;
        const float r2 = h * h + b * b;
        const float r = r2 > 0.f ? sqrtf(r2) : 0.f;
        if (r > 0.f) {
          da = 0.5f - h / (2.f * r);
          dc = 0.5f + h / (2.f * r);
          db = -b / r;
        } else {
          da = dc = 0.5f;
          db = 0.f;
        }
        lam = (a + c) / 2.f - r;
      }
      if (lam < 0) {
        l.x = lam * lam;
        const float gl = wx * 2.f * lam;
        adj[c0] += gl * da;
        if (D == 2) {
          adj[c0 + 1] += gl * db;
          adj[c0 + 2] += gl * dc;
        }
      }
    }
  }
  return l;
}

// The data losses of a chunk (twin of cpu::data_losses) on ch.out, writing the adjoint ch.dout
// (every channel) when grad; per-point terms into ch.lp, summed by warp 0 into *out (lane 0).
template <int D, int ORDER>
__device__ void chunk_data_losses(const LossCfg& cfg, int np, float scale, bool grad, Chunk& ch, Sums5* sum) {
  constexpr int C = jet_channels(D, ORDER);
  const float wz = float(cfg.wz) * scale, wf = float(cfg.wf) * scale, wc = float(cfg.wc) * scale,
              wx = float(cfg.wx) * scale;
  const int S = ch.S;
  for (int p = threadIdx.x; p < np; p += blockDim.x) {
    float jet[C], adj[C];
#pragma unroll
    for (int c = 0; c < C; ++c) jet[c] = ch.out[c * np + p];
    const PointLoss l = point_data_loss<D, ORDER>(cfg, wz, wf, wc, wx, jet, ch.y[p], &ch.g[p * D], adj);
    if (grad) {
#pragma unroll
      for (int c = 0; c < C; ++c) ch.dout[c * np + p] = adj[c];
    }
    ch.lp[0 * S + p] = l.z;
    ch.lp[1 * S + p] = l.f;
    ch.lp[2 * S + p] = l.c;
    ch.lp[3 * S + p] = l.x;
  }
  __syncthreads();
  float r[4];
  warp0_sum(ch.lp, S, np, 4, r);
  if (threadIdx.x == 0) {
    sum->z += r[0];
    sum->f += r[1];
    sum->c += r[2];
    sum->x += r[3];
  }
}

// The strain-concentration loss of a chunk of off-domain points (twin of
// cpu::strain_concentration_loss; order-1 jet): normals in ch.nrm [np, D].
template <int D>
__device__ void chunk_offdomain_loss(int np, float weight_scale, bool grad, Chunk& ch, Sums5* sum) {
  const int S = ch.S;
  for (int p = threadIdx.x; p < np; p += blockDim.x) {
    float dot = 0.f;
#pragma unroll
    for (int i = 0; i < D; ++i) dot += ch.out[(1 + i) * np + p] * ch.nrm[p * D + i];
    float l = 0.f;
    if (grad) ch.dout[p] = 0.f;
#pragma unroll
    for (int i = 0; i < D; ++i)
      if (grad) ch.dout[(1 + i) * np + p] = dot < 0 ? weight_scale * 2.f * dot * ch.nrm[p * D + i] : 0.f;
    if (dot < 0) l = dot * dot;
    ch.lp[p] = l;
  }
  __syncthreads();
  float r[1];
  warp0_sum(ch.lp, S, np, 1, r);
  if (threadIdx.x == 0) sum->s += r[0];
}

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
