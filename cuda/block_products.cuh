#pragma once
// The block-wide products and sums of a chunk in shared memory: the tiled matrix product of a
// layer's jet (forward and transposed), the weight gradient over a chunk's columns in slices,
// and the fixed-order column and warp sums. Every sum has a fixed order (cuda/jet_block.cuh).
#include <cstddef>
#include <cstdint>

#include "cuda/jet_shape.cuh"

namespace yarnhom::cuda::detail {

#ifdef __CUDACC__

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

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
