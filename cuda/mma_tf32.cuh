#pragma once
// The tensor-core building blocks of the warp path (cuda/mma_jet.cuh, whose header explains
// the layout): the 3xTF32 split and the m16n8k8 TF32 MMA, the lane-private float4 slots of a
// warp's buffers, the weights' B fragments (made once per block), and the two kinds of product
// of a tile: a layer's jet times a weight matrix (forward and input adjoint) and the weight
// gradient over the tile's rows.
#include <cstdint>

#include "cuda/jet_shape.cuh"

namespace yarnhom::cuda::detail {

#ifdef __CUDACC__

// ---- the MMA and the 3xTF32 split ----
struct Tf32x4 {
  uint32_t big[4], small[4];
};

// tf32(x) rounded to nearest, ties away from zero: cvt.rna.tf32.f32 for finite x and infinities,
// written as the two integer operations it amounts to (add half of the 13 dropped mantissa
// bits to the magnitude, then clear them; a carry moves into the exponent as it should).
// ptxas emits the PTX conversion as these two plus a compare that keeps NaN payloads intact
// (seen in the SASS on sm_90); the split below is on the hot path (about 60 splits per point
// at d = 2).
__device__ inline uint32_t tf32_rna(float x) { return (__float_as_uint(x) + 0x1000u) & 0xffffe000u; }
// x = big + small + O(2^-22 |x|), big and small TF32 (round to nearest); x - big is exact.
__device__ inline void split_tf32(float x, uint32_t& big, uint32_t& small) {
  big = tf32_rna(x);
  small = tf32_rna(x - __uint_as_float(big));
}
__device__ inline Tf32x4 split4(float a0, float a1, float a2, float a3) {
  Tf32x4 f;
  split_tf32(a0, f.big[0], f.small[0]);
  split_tf32(a1, f.big[1], f.small[1]);
  split_tf32(a2, f.big[2], f.small[2]);
  split_tf32(a3, f.big[3], f.small[3]);
  return f;
}

// d += A B, one m16n8k8 TF32 MMA with FP32 accumulation.
__device__ inline void mma_tf32(float4& d, const uint32_t (&a)[4], uint32_t b0, uint32_t b1) {
  asm("mma.sync.aligned.m16n8k8.row.col.f32.tf32.tf32.f32 {%0,%1,%2,%3}, {%4,%5,%6,%7}, {%8,%9}, "
      "{%0,%1,%2,%3};"
      : "+f"(d.x), "+f"(d.y), "+f"(d.z), "+f"(d.w)
      : "r"(a[0]), "r"(a[1]), "r"(a[2]), "r"(a[3]), "r"(b0), "r"(b1));
}
// 3xTF32: d += A B to about float accuracy. b = (b0 big, b1 big, b0 small, b1 small).
__device__ inline void mma3(float4& d, const Tf32x4& a, uint32_t b0b, uint32_t b1b, uint32_t b0s, uint32_t b1s) {
  mma_tf32(d, a.small, b0b, b1b);
  mma_tf32(d, a.big, b0s, b1s);
  mma_tf32(d, a.big, b0b, b1b);
}
// The same with the B fragment as a float4 of mma_prepare_frags.
__device__ inline void mma3(float4& d, const Tf32x4& a, const float4& b) {
  mma3(d, a, __float_as_uint(b.x), __float_as_uint(b.y), __float_as_uint(b.z), __float_as_uint(b.w));
}

// The lane-private float4 slot of a lane (lanes 8..15 and 24..31 swizzled, see above).
__device__ inline int lslot(int lane) { return lane ^ (((lane >> 3) & 1) << 2); }

// Element (row r of m-tile mt, neuron n) of a warp buffer whose rows hold NT neuron tiles.
template <int NT>
__device__ inline float buf_elem(const float* b, int mt, int r, int n) {
  const int lane = (r & 7) * 4 + ((n & 7) >> 1);
  return b[((mt * NT + (n >> 3)) * 32 + lslot(lane)) * 4 + (n & 1) + 2 * (r >> 3)];
}

// ---- weight fragments (once per block) ----
// Fragment f of layer-matrix M (rows x cols, row-major at W with row stride ld), as the B
// operand of k-tile kt and n-tile nt, with k along M's columns (forward: B = W^T, k = in,
// n = out) when !trans, along M's rows (reverse: B = W, k = out, n = in) when trans. Lane
// (g, t): b0 = (k = 8kt + 2t, n = 8nt + g), b1 = (k = 8kt + 2t + 1, n = 8nt + g).
__device__ inline float4 make_bfrag(const float* W, int ld, bool trans, int kt, int nt, int lane) {
  const int g = lane >> 2, t = lane & 3;
  const int k0 = 8 * kt + 2 * t, n = 8 * nt + g;
  const float v0 = trans ? W[k0 * ld + n] : W[n * ld + k0];
  const float v1 = trans ? W[(k0 + 1) * ld + n] : W[n * ld + k0 + 1];
  uint32_t b0, s0, b1, s1;
  split_tf32(v0, b0, s0);
  split_tf32(v1, b1, s1);
  return make_float4(__uint_as_float(b0), __uint_as_float(b1), __uint_as_float(s0), __uint_as_float(s1));
}
// frag layout: [fwd1 (kt 2 x nt 4), bwd1 (kt 4 x nt 2), fwd2 (kt 4 x nt 2), bwd2 (kt 2 x nt 4)] x 32 lanes.
__device__ inline void mma_prepare_frags(const NetShape& s, const float* W, float4* frag) {
  for (int i = threadIdx.x; i < 4 * 8 * 32; i += blockDim.x) {
    const int lane = i & 31, f = (i >> 5) & 7, which = i >> 8;
    const int k = which < 2 ? 1 : 2;  // layer
    const bool trans = which & 1;
    const int nts = trans ? s.in[k] / 8 : s.out[k] / 8;
    frag[i] = make_bfrag(W + s.woff[k], s.in[k], trans, f / nts, f % nts, lane);
  }
}

// ---- the products ----
// dst = src W^T (+ bias on channel 0) per m-tile: src has IN/8 neuron tiles (its stride SNT),
// dst OUT/8 (stride DNT); frag: [IN/8][OUT/8] B fragments. Forward (W^T) and reverse (W) use
// the same code with their own fragments; the reverse passes bias = nullptr.
// U: m-tiles unrolled together (more independent MMA chains; more registers).
template <int MT, int IN, int OUT, int SNT, int DNT, int U = 1>
__device__ inline void mma_layer(const float4* src, float4* dst, const float4* frag, const float* bias, int lane) {
  const int sl = lslot(lane), t = lane & 3;
#pragma unroll(U)
  for (int mt = 0; mt < MT; ++mt) {
    Tf32x4 a[IN / 8];
#pragma unroll
    for (int kt = 0; kt < IN / 8; ++kt) {
      const float4 v = src[(mt * SNT + kt) * 32 + sl];
      a[kt] = split4(v.x, v.z, v.y, v.w);  // a0 = c0, a1 = c2, a2 = c1, a3 = c3
    }
    // Independent accumulator chains: with only 2 n-tiles (OUT = 16) the k-tiles alternate
    // between two partial sums, added at the end, so that 4 MMA chains are in flight (a chain
    // of dependent MMAs waits out the tensor pipe's latency at every step).
    constexpr int NP = (OUT / 8 >= 4 || IN / 8 < 2) ? 1 : 2;
#pragma unroll
    for (int nt = 0; nt < OUT / 8; ++nt) {
      float4 part[NP];
#pragma unroll
      for (int q = 0; q < NP; ++q) part[q] = make_float4(0.f, 0.f, 0.f, 0.f);
#pragma unroll
      for (int kt = 0; kt < IN / 8; ++kt) mma3(part[kt % NP], a[kt], frag[(kt * (OUT / 8) + nt) * 32 + lane]);
      float4 acc = part[0];
#pragma unroll
      for (int q = 1; q < NP; ++q) {
        acc.x += part[q].x;
        acc.y += part[q].y;
        acc.z += part[q].z;
        acc.w += part[q].w;
      }
      if (bias != nullptr && mt == 0) {  // row g of m-tile 0 is channel 0
        acc.x += bias[8 * nt + 2 * t];
        acc.y += bias[8 * nt + 2 * t + 1];
      }
      dst[(mt * DNT + nt) * 32 + sl] = acc;
    }
  }
}

// acc[om][nt] += sum over the tile's rows of Zbar[row][16 om + .] A[row][8 nt + .]: the weight
// gradient of a layer with OUT outputs (zbar: OUT/8 neuron tiles, stride ZNT) and IN inputs
// (act: stride ANT). Reads other lanes' slots: the caller __syncwarp()s before and after.
template <int MT, int OUT, int IN, int ZNT, int ANT>
__device__ inline void mma_weight_grad(const float* zbar, const float* act, float4 (&acc)[OUT / 16][IN / 8],
                                       int mts, int lane) {
  const int g = lane >> 2, t = lane & 3;
#pragma unroll 1
  for (int mt = 0; mt < mts; ++mt) {
#pragma unroll
    for (int ks = 0; ks < 2; ++ks) {
      const int r0 = 8 * ks + 2 * t, r1 = r0 + 1;
      Tf32x4 a[OUT / 16];
#pragma unroll
      for (int om = 0; om < OUT / 16; ++om)
        a[om] = split4(buf_elem<ZNT>(zbar, mt, r0, 16 * om + g), buf_elem<ZNT>(zbar, mt, r0, 16 * om + g + 8),
                       buf_elem<ZNT>(zbar, mt, r1, 16 * om + g), buf_elem<ZNT>(zbar, mt, r1, 16 * om + g + 8));
#pragma unroll
      for (int nt = 0; nt < IN / 8; ++nt) {
        uint32_t b0b, b0s, b1b, b1s;
        split_tf32(buf_elem<ANT>(act, mt, r0, 8 * nt + g), b0b, b0s);
        split_tf32(buf_elem<ANT>(act, mt, r1, 8 * nt + g), b1b, b1s);
#pragma unroll
        for (int om = 0; om < OUT / 16; ++om) mma3(acc[om][nt], a[om], b0b, b1b, b0s, b1s);
      }
    }
  }
}

// mma_weight_grad over all MT m-tiles of the warp buffers zbar and act, between the two
// __syncwarp()s its reads of other lanes' slots need.
template <int MT, int OUT, int IN, int ZNT, int ANT>
__device__ __forceinline__ void mma_weight_grad_synced(const float4* zbar, const float4* act,
                                                       float4 (&acc)[OUT / 16][IN / 8], int lane) {
  __syncwarp();
  mma_weight_grad<MT, OUT, IN, ZNT, ANT>(reinterpret_cast<const float*>(zbar), reinterpret_cast<const float*>(act),
                                         acc, MT, lane);
  __syncwarp();
}

// Channel c of the lane's neuron e (0: 2t, 1: 2t + 1) in the float4 of m-tile c / 2.
__device__ inline float& jet_comp(float4 (&q)[8], int c, int e) {
  float4& v = q[c >> 1];
  const int i = 2 * (c & 1) + e;
  return i == 0 ? v.x : i == 1 ? v.y : i == 2 ? v.z : v.w;
}

// The lane's float4s of neuron tile nt in the MT m-tiles of a warp buffer whose rows hold snt
// neuron tiles, and back.
template <int MT>
__device__ __forceinline__ void load_jet_tiles(float4 (&q)[8], const float4* slot, int snt, int nt, int sl) {
#pragma unroll
  for (int mt = 0; mt < MT; ++mt) q[mt] = slot[(mt * snt + nt) * 32 + sl];
}
template <int MT>
__device__ __forceinline__ void store_jet_tiles(const float4 (&q)[8], float4* slot, int snt, int nt, int sl) {
#pragma unroll
  for (int mt = 0; mt < MT; ++mt) slot[(mt * snt + nt) * 32 + sl] = q[mt];
}
// The same for two buffers at once, their loads (stores) interleaved m-tile by m-tile.
template <int MT>
__device__ __forceinline__ void load_jet_tiles(float4 (&q)[8], const float4* slot, int snt, float4 (&q2)[8],
                                               const float4* slot2, int snt2, int nt, int sl) {
#pragma unroll
  for (int mt = 0; mt < MT; ++mt) {
    q[mt] = slot[(mt * snt + nt) * 32 + sl];
    q2[mt] = slot2[(mt * snt2 + nt) * 32 + sl];
  }
}
template <int MT>
__device__ __forceinline__ void store_jet_tiles(const float4 (&q)[8], float4* slot, int snt, const float4 (&q2)[8],
                                                float4* slot2, int snt2, int nt, int sl) {
#pragma unroll
  for (int mt = 0; mt < MT; ++mt) {
    slot[(mt * snt + nt) * 32 + sl] = q[mt];
    slot2[(mt * snt2 + nt) * 32 + sl] = q2[mt];
  }
}
// The C channels of the lane's neuron e out of its m-tiles' float4s, and back (the channels
// above C, up to 2 MT, set to zero); the two-buffer forms interleave them channel by channel.
template <int C>
__device__ __forceinline__ void get_jet(float4 (&q)[8], int e, float (&v)[C]) {
#pragma unroll
  for (int c = 0; c < C; ++c) v[c] = jet_comp(q, c, e);
}
template <int C, int MT>
__device__ __forceinline__ void put_jet(float4 (&q)[8], int e, const float (&v)[C]) {
#pragma unroll
  for (int c = 0; c < 2 * MT; ++c) jet_comp(q, c, e) = c < C ? v[c] : 0.f;
}
template <int C>
__device__ __forceinline__ void get_jet(float4 (&q)[8], float4 (&q2)[8], int e, float (&v)[C], float (&v2)[C]) {
#pragma unroll
  for (int c = 0; c < C; ++c) {
    v[c] = jet_comp(q, c, e);
    v2[c] = jet_comp(q2, c, e);
  }
}
template <int C, int MT>
__device__ __forceinline__ void put_jet(float4 (&q)[8], float4 (&q2)[8], int e, const float (&v)[C],
                                        const float (&v2)[C]) {
#pragma unroll
  for (int c = 0; c < 2 * MT; ++c) {
    jet_comp(q, c, e) = c < C ? v[c] : 0.f;
    jet_comp(q2, c, e) = c < C ? v2[c] : 0.f;
  }
}

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
