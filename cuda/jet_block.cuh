#pragma once
// Block-level building blocks of the CUDA backend: one thread block runs the jet forward pass,
// the losses and the reverse pass of a *chunk* of points entirely in shared memory. Every CUDA
// entry point (the twins in cuda/api.cu, the fused epoch kernel in cuda/cuda_backend.cu) is
// made of these functions, except mlp_loss_grad of Net-3, which runs on the tensor-core warp
// path of cuda/mma_jet.cuh (it shares the per-point sigmoid jets and losses below).
//
// The math is the CPU's (cpu/mlp_jet.hpp, cpu/sigmoid_jet.hpp, cpu/losses.cpp); so is the
// layout of a jet inside a chunk of np points: a layer's jet is [n, S] with channel c of point
// p in column c*np + p (the CPU's [n, C*B] with B = np), S >= C*np the row stride. S is kept
// at 4 mod 32 floats so that the float4 loads of the gradient sums, whose lanes walk down the
// rows, hit distinct banks.
//
// Determinism: every sum (a matrix product's inner sum, a weight gradient over a chunk's
// columns, the loss terms over its points) is computed by one thread in a fixed order, or by a
// fixed shuffle tree; a chunk's gradient is added into the block's gradient by the one thread
// that owns that parameter, chunk after chunk. No atomics anywhere.
#include <cstdint>
#include <cstddef>

#include "core/jet_layout.hpp"
#include "core/network.hpp"
#include "core/offdomain.hpp"

namespace yarnhom::cuda::detail {

inline constexpr int kMaxLayers = 8;

// A network's shape, flat and trivially copyable, for kernels (core/network.hpp's layout).
struct NetShape {
  int d = 1, L = 0, P = 0;
  int in[kMaxLayers] = {}, out[kMaxLayers] = {};
  int woff[kMaxLayers] = {}, boff[kMaxLayers] = {};
  int hoff[kMaxLayers] = {};  // first row of hidden layer k in the z/a stacks
  int hsum = 0, hmax = 0;     // sum and max of the hidden widths
};

inline NetShape make_shape(const NetworkDesc& desc) {
  desc.validate();
  NetShape s;
  s.d = desc.input_dim;
  s.L = desc.num_layers();
  if (s.L > kMaxLayers) throw std::invalid_argument("the CUDA backend takes at most 7 hidden layers");
  s.P = desc.num_params();
  for (int k = 0; k < s.L; ++k) {
    s.in[k] = desc.layer_in(k);
    s.out[k] = desc.layer_out(k);
    s.woff[k] = desc.weight_offset(k);
    s.boff[k] = desc.bias_offset(k);
    if (k < s.L - 1) {
      s.hoff[k] = s.hsum;
      s.hsum += s.out[k];
      s.hmax = s.out[k] > s.hmax ? s.out[k] : s.hmax;
    }
  }
  return s;
}

// Loss configuration in the form the kernels use (cpu::LossOptions, exact L_C only).
struct LossCfg {
  double wz = 1, wf = 0.05, wc = 1e-3, ws = 1e2, wx = 0;
  int order = 3;  // data jet order (cpu::data_jet_order)
};

// Per-point loss terms of a chunk are reduced by warp 0 with this fixed tree.
struct Sums5 {
  float z = 0, f = 0, c = 0, s = 0, x = 0;
};

// Floats of shared scratch for the weight-gradient partial tiles (chunk_backward).
inline constexpr int kDwScratch = 4096;

inline int round4(int n) { return (n + 3) & ~3; }
// The smallest stride >= n with stride = 4 mod 32.
YH_HD inline int chunk_stride(int n) {
  int s = (n + 3) & ~3;
  while (s % 32 != 4) s += 4;
  return s;
}

// Floats of shared memory for the chunk buffers of stride S (each part a multiple of 4).
struct ChunkLayout {
  int z, a, out, dout, bufA, bufB, x, y, g, nrm, lp, dwp, total;
};
YH_HD inline ChunkLayout chunk_layout(const NetShape& s, int S, int base) {
  ChunkLayout c;
  int o = base;
  auto take = [&](int n) {
    const int at = o;
    o += (n + 3) & ~3;
    return at;
  };
  c.z = take(s.hsum * S);
  c.a = take(s.hsum * S);
  c.out = take(S);
  c.dout = take(S);
  c.bufA = take(s.hmax * S);
  c.bufB = take(s.hmax * S);
  c.x = take(S * s.d);
  c.y = take(S);
  c.g = take(S * s.d);
  c.nrm = take(S * s.d);
  c.lp = take(4 * S);
  c.dwp = take(kDwScratch);
  c.total = o;
  return c;
}

#ifdef __CUDACC__

// Pointers into shared memory for one chunk.
struct Chunk {
  float *z, *a, *out, *dout, *bufA, *bufB, *x, *y, *g, *nrm, *lp, *dwp;
  int S;
};
__device__ inline Chunk make_chunk(float* smem, const ChunkLayout& l, int S) {
  return Chunk{smem + l.z, smem + l.a,   smem + l.out, smem + l.dout, smem + l.bufA, smem + l.bufB,
               smem + l.x, smem + l.y,   smem + l.g,   smem + l.nrm,  smem + l.lp,   smem + l.dwp, S};
}

__device__ inline void fma4(float4& acc, float w, const float4& v) {
  acc.x = fmaf(w, v.x, acc.x);
  acc.y = fmaf(w, v.y, acc.y);
  acc.z = fmaf(w, v.z, acc.z);
  acc.w = fmaf(w, v.w, acc.w);
}

// out[r][col] = sum_j M(r, j) in[j][col] (+ bias[r] in the columns < nb), M(r, j) =
// Wp[r*rs + j*js], for r < rows and the first ncol columns (rounded up to 4; the extra columns
// hold whatever the padding computes to and are never read as data). A thread owns a 4x4 tile
// (4 rows, 4 consecutive columns). The weights are read as float4 when the layout allows:
// along j (js == 1, the forward product) or along r (rs == 1, the transposed one); the sum
// over j is in increasing j either way.
__device__ inline void block_gemm(const float* Wp, int rs, int js, const float* bias, int nb, int rows,
                                  int inner, const float* in, float* out, int S, int ncol) {
  const int nc4 = (ncol + 3) >> 2, rt = (rows + 3) >> 2, tiles = rt * nc4;
  const bool aligned = (reinterpret_cast<uintptr_t>(Wp) & 15) == 0;
  const bool vec_j = aligned && js == 1 && (rs & 3) == 0 && (inner & 3) == 0;
  const bool vec_r = aligned && rs == 1 && (js & 3) == 0 && !vec_j;
  for (int t = threadIdx.x; t < tiles; t += blockDim.x) {
    const int c4 = t % nc4, r0 = (t / nc4) * 4;
    float4 acc[4];
    for (int q = 0; q < 4; ++q) acc[q] = make_float4(0.f, 0.f, 0.f, 0.f);
    const int rr[4] = {min(r0, rows - 1), min(r0 + 1, rows - 1), min(r0 + 2, rows - 1), min(r0 + 3, rows - 1)};
    const float* ip = in + 4 * c4;
    if (vec_j) {
      for (int j = 0; j < inner; j += 4) {
        const float4 v0 = *reinterpret_cast<const float4*>(ip + (j + 0) * S);
        const float4 v1 = *reinterpret_cast<const float4*>(ip + (j + 1) * S);
        const float4 v2 = *reinterpret_cast<const float4*>(ip + (j + 2) * S);
        const float4 v3 = *reinterpret_cast<const float4*>(ip + (j + 3) * S);
#pragma unroll
        for (int q = 0; q < 4; ++q) {
          const float4 w = *reinterpret_cast<const float4*>(Wp + rr[q] * rs + j);
          fma4(acc[q], w.x, v0);
          fma4(acc[q], w.y, v1);
          fma4(acc[q], w.z, v2);
          fma4(acc[q], w.w, v3);
        }
      }
    } else if (vec_r && r0 + 3 < rows) {
      for (int j = 0; j < inner; ++j) {
        const float4 v = *reinterpret_cast<const float4*>(ip + j * S);
        const float4 w = *reinterpret_cast<const float4*>(Wp + r0 + j * js);
        fma4(acc[0], w.x, v);
        fma4(acc[1], w.y, v);
        fma4(acc[2], w.z, v);
        fma4(acc[3], w.w, v);
      }
    } else {
      for (int j = 0; j < inner; ++j) {
        const float4 v = *reinterpret_cast<const float4*>(ip + j * S);
#pragma unroll
        for (int q = 0; q < 4; ++q) fma4(acc[q], Wp[rr[q] * rs + j * js], v);
      }
    }
#pragma unroll
    for (int q = 0; q < 4; ++q) {
      const int r = r0 + q;
      if (r >= rows) break;
      float4 o = acc[q];
      if (bias) {
        const int c = 4 * c4;
        const float b = bias[r];
        if (c + 0 < nb) o.x += b;
        if (c + 1 < nb) o.y += b;
        if (c + 2 < nb) o.z += b;
        if (c + 3 < nb) o.w += b;
      }
      *reinterpret_cast<float4*>(out + r * S + 4 * c4) = o;
    }
  }
}

// The weight gradient of a layer over a chunk, in two phases around a barrier:
// dw_partials: dW[r][j] = sum over columns zbar[r][col] a[j][col], a thread per 4x4 tile of
//   (r, j) and per slice of the columns (float4 steps; the last slice takes the tail), written
//   to the scratch as [slice][16 entries][tile];
// dw_reduce: a thread per weight sums its tile entry over the slices in slice order and adds it
//   into G. Both orders are fixed by (n, m, N, blockDim), so the result is deterministic.
struct DwPlan {
  int rt, jt, tiles, slices, n4;
};
__device__ inline DwPlan dw_plan(int n, int m, int N) {
  DwPlan p;
  p.rt = (n + 3) >> 2;
  p.jt = (m + 3) >> 2;
  p.tiles = p.rt * p.jt;
  p.n4 = N >> 2;
  int q = int(blockDim.x) / p.tiles;
  q = min(q, kDwScratch / (16 * p.tiles));
  q = min(q, max(1, p.n4 / 2));  // at least two float4 steps per slice
  p.slices = max(1, q);
  return p;
}
__device__ inline void dw_partials(const DwPlan& p, const float* zbar, const float* A, int n, int m, int N, int S,
                                   float* scratch) {
  for (int w = threadIdx.x; w < p.tiles * p.slices; w += blockDim.x) {
    const int t = w % p.tiles, q = w / p.tiles;
    const int r0 = (t / p.jt) * 4, j0 = (t % p.jt) * 4;
    const float* zr[4];
    const float* aj[4];
#pragma unroll
    for (int u = 0; u < 4; ++u) {
      zr[u] = zbar + min(r0 + u, n - 1) * S;
      aj[u] = A + min(j0 + u, m - 1) * S;
    }
    float acc[4][4];
#pragma unroll
    for (int u = 0; u < 4; ++u)
#pragma unroll
      for (int v = 0; v < 4; ++v) acc[u][v] = 0.f;
    const int c_begin = (q * p.n4) / p.slices, c_end = ((q + 1) * p.n4) / p.slices;
    for (int c = c_begin; c < c_end; ++c) {
      float4 zv[4], av[4];
#pragma unroll
      for (int u = 0; u < 4; ++u) {
        zv[u] = reinterpret_cast<const float4*>(zr[u])[c];
        av[u] = reinterpret_cast<const float4*>(aj[u])[c];
      }
#pragma unroll
      for (int u = 0; u < 4; ++u)
#pragma unroll
        for (int v = 0; v < 4; ++v) {
          acc[u][v] = fmaf(zv[u].x, av[v].x, acc[u][v]);
          acc[u][v] = fmaf(zv[u].y, av[v].y, acc[u][v]);
          acc[u][v] = fmaf(zv[u].z, av[v].z, acc[u][v]);
          acc[u][v] = fmaf(zv[u].w, av[v].w, acc[u][v]);
        }
    }
    if (q == p.slices - 1)
      for (int c = 4 * p.n4; c < N; ++c)
#pragma unroll
        for (int u = 0; u < 4; ++u)
#pragma unroll
          for (int v = 0; v < 4; ++v) acc[u][v] = fmaf(zr[u][c], aj[v][c], acc[u][v]);
    // [slice][entry][tile]: a warp's lanes (consecutive tiles) store to consecutive words.
    float* o = scratch + size_t(q) * 16 * p.tiles + t;
#pragma unroll
    for (int u = 0; u < 4; ++u)
#pragma unroll
      for (int v = 0; v < 4; ++v) o[(u * 4 + v) * p.tiles] = acc[u][v];
  }
}
__device__ inline void dw_reduce(const DwPlan& p, const float* scratch, int n, int m, float* Gw) {
  for (int t = threadIdx.x; t < n * m; t += blockDim.x) {
    const int r = t / m, j = t % m;
    const int tile = (r >> 2) * p.jt + (j >> 2), e = (r & 3) * 4 + (j & 3);
    float sum = scratch[size_t(e) * p.tiles + tile];
    for (int q = 1; q < p.slices; ++q) sum += scratch[(size_t(q) * 16 + e) * p.tiles + tile];
    Gw[t] += sum;
  }
}

__device__ inline float sum_cols(const float* u, int n) {
  float s = 0.f;
  for (int i = 0; i < n; ++i) s += u[i];
  return s;
}

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

// Warp 0 sums lp[q*S + p] over p < np for q < nq in a fixed order (lane-strided sums, then a
// shuffle tree); the result is in lane 0 of warp 0.
__device__ inline void warp0_sum(const float* lp, int S, int np, int nq, float* res) {
  if (threadIdx.x >= 32) return;
  for (int q = 0; q < nq; ++q) {
    float v = 0.f;
    for (int p = threadIdx.x; p < np; p += 32) v += lp[q * S + p];
#pragma unroll
    for (int o = 16; o > 0; o >>= 1) v += __shfl_down_sync(0xffffffffu, v, o);
    if (threadIdx.x == 0) res[q] = v;
  }
}

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


// Where a batch's points come from. Data point i of the batch is row idx[i] (or i when idx is
// null) of x [*, D], y, g. Off-domain points are either given (xo, no [k, D]) or drawn on the
// fly from the stream okey with core/offdomain.hpp (the CPU backend's exact points).
struct BatchSrc {
  int m = 0;
  const float *x = nullptr, *y = nullptr, *g = nullptr;
  const int* idx = nullptr;
  int k = 0;  // 0: no off-domain term
  const float *xo = nullptr, *no = nullptr;
  uint64_t okey = 0;
};

// Chunks of a batch: the data points in chunks of S/C, then the off-domain points in chunks of
// S/(1+D) (order-1 jets), numbered in that order (the CPU's tasks, cpu/loss_step.cpp).
struct TaskPlan {
  int cap_d, cap_o, nd, no;
  YH_HD int tasks() const { return nd + no; }
};
template <int D, int ORDER>
YH_HD inline TaskPlan plan_tasks(int S, int m, int k) {
  TaskPlan t;
  t.cap_d = S / jet_channels(D, ORDER);
  t.cap_o = S / jet_channels(D, 1);
  t.nd = (m + t.cap_d - 1) / t.cap_d;
  t.no = k > 0 ? (k + t.cap_o - 1) / t.cap_o : 0;
  return t;
}

// Runs tasks first, first + stride, ... of a batch in this block: forward jets, losses, and
// (when G is non-null) the reverse pass, adding each task's gradient into G in task order.
// The loss sums of the tasks are added into *sum (thread 0). inv_m, inv_k: 1/M and 1/K of the
// whole batch (cpu::mlp_loss_grad's scales).
template <int D, int ORDER>
__device__ void batch_tasks(const NetShape& s, const float* W, const LossCfg& cfg, const BatchSrc& src,
                            float inv_m, float inv_k, Chunk& ch, float* G, Sums5* sum, int first, int stride) {
  const TaskPlan tp = plan_tasks<D, ORDER>(ch.S, src.m, src.k);
  const bool grad = G != nullptr;
  for (int t = first; t < tp.tasks(); t += stride) {
    if (t < tp.nd) {
      const int begin = t * tp.cap_d, np = min(tp.cap_d, src.m - begin);
      for (int p = threadIdx.x; p < np; p += blockDim.x) {
        const int i = src.idx ? src.idx[begin + p] : begin + p;
        ch.y[p] = src.y[i];
#pragma unroll
        for (int q = 0; q < D; ++q) {
          ch.x[p * D + q] = src.x[size_t(i) * D + q];
          ch.g[p * D + q] = src.g[size_t(i) * D + q];
        }
      }
      __syncthreads();
      chunk_forward<D, ORDER>(s, W, np, ch);
      chunk_data_losses<D, ORDER>(cfg, np, inv_m, grad, ch, sum);
      if (grad) chunk_backward<D, ORDER>(s, W, np, ch, G);
    } else {
      const int begin = (t - tp.nd) * tp.cap_o, np = min(tp.cap_o, src.k - begin);
      for (int p = threadIdx.x; p < np; p += blockDim.x) {
        if (src.xo) {
#pragma unroll
          for (int q = 0; q < D; ++q) {
            ch.x[p * D + q] = src.xo[size_t(begin + p) * D + q];
            ch.nrm[p * D + q] = src.no[size_t(begin + p) * D + q];
          }
        } else {
          offdomain_point<float>(D, src.okey, uint64_t(begin + p), &ch.x[p * D], &ch.nrm[p * D]);
        }
      }
      __syncthreads();
      chunk_forward<D, 1>(s, W, np, ch);
      chunk_offdomain_loss<D>(np, float(cfg.ws) * inv_k, grad, ch, sum);
      if (grad) chunk_backward<D, 1>(s, W, np, ch, G);
    }
    __syncthreads();
  }
}

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
