#pragma once
// The tensor-core warp path of the fused loss + gradient (cuda::mlp_loss_grad) for the paper's
// Net-3 (d -> 16 -> 32 -> 16 -> 1): the three products of every hidden-to-hidden layer run as
// warp-level tensor-core MMAs (mma.sync m16n8k8, TF32 inputs, FP32 accumulation) in 3xTF32,
// which keeps float accuracy; layer 0 (in = d), the output layer (out = 1), the sigmoid jet maps
// and the losses run on the CUDA cores. Same math as cuda/jet_block.cuh's block path and the
// CPU twin (cpu/loss_step.cpp); other network shapes take the block path.
//
// Why a warp and not a block. The block path keeps a chunk's jets in shared memory, does the
// products as 4x4 register tiles and needs a block barrier between every two phases; Nsight
// found it bound by the shared-memory pipe and by barrier stalls, with ~4 warp instructions
// per FMA. Here one warp owns a *tile* of 8 points and runs its whole forward pass, losses and
// reverse pass alone: no block barriers, and, except for the weight-gradient products, every
// lane only reads back what it wrote itself.
//
// The layout that makes that possible. A layer's jet over the tile is the matrix
// [rows = (point, channel), columns = neurons], and every product is computed as
//   Z^T = A^T W^T (forward),   Abar^T = Zbar^T W (input adjoint),   dW = Zbar^T-by-A over rows,
// i.e. with the points on the MMA's M side. With g = lane / 4 and t = lane % 4, an m16n8 C
// fragment gives lane (g, t) the rows g and g + 8 and the neurons 2t, 2t + 1 of its 8-wide
// neuron tile. Row g of m-tile mt is channel 2 mt of point g, row g + 8 is channel 2 mt + 1 of
// the same point (ceil(C/2) m-tiles; an odd C leaves one zero channel). So a lane holds *every
// channel* of its (point, neuron) pairs: the sigmoid jet map (which mixes channels, not points
// or neurons) runs in the lane with no exchange. And the C fragment is already the next
// product's A fragment, because the sum over k may visit the neurons in any order: k-slot t
// of a k-tile is neuron 2t, k-slot t + 4 is neuron 2t + 1 (a0 = c0, a1 = c2, a2 = c1,
// a3 = c3); the weights' B fragments are loaded with the same neuron order.
//
// The weight gradient dW = sum over rows of Zbar[row][out] A[row][in] has the rows on the
// MMA's K side, so both operands need the transposed fragment (row on t, neuron on g). Those
// are read back from the other lanes' shared-memory slots after a __syncwarp, with the rows
// permuted the same way (k-slot t = row 2t, t + 4 = row 2t + 1); the slots of lanes 8..15 and
// 24..31 are swizzled (lane ^ 4) so these scalar reads are at most 2-way bank conflicted.
//
// 3xTF32: every operand x is split into big = tf32(x) (round to nearest) and
// small = tf32(x - big); acc += a_small b_big + a_big b_small + a_big b_big (small terms first;
// a_small b_small, ~2^-22 relative, is dropped). The weights' splits are made once per block.
//
// Storage per warp (shared memory, lane-private float4 slots [m-tile][neuron tile][lane]):
// slot1, slot2: the pre-activation jets z of hidden layers 1 and 2, overwritten by their
// adjoints zbar in the reverse pass; buf: the activation a of the layer being fed forward (a2
// stays there for the output layer's reverse), then the input adjoints abar, then the
// activations recomputed for the weight gradient. Layer 0's z (= W0 x + b0, W0's columns,
// zeros) is recomputed from x in the reverse pass, and a0, a1 from z (the reverse pass needs
// a for the weight gradients, z for the sigmoid jets' reverse; holding both would halve the
// warps that fit in shared memory).
//
// Determinism: an MMA's sum has the hardware's fixed order; a warp accumulates its tiles in a
// fixed sequence (the weight gradients in MMA accumulators across tiles, the rest in
// per-lane registers), lanes are combined by fixed shuffle trees (xor 4, 8, 16 over the points,
// xor 1, 2 over a point's neuron quarters), warps in warp order, blocks in block order. No
// atomics.
#include <cstdint>

#include "cuda/jet_block.cuh"

namespace yarnhom::cuda::detail {

// Hidden widths the warp path is compiled for (the paper's Net-3).
inline constexpr int kMmaH0 = 16, kMmaH1 = 32, kMmaH2 = 16;

inline bool mma_path_fits(const NetShape& s) {
  return s.L == 4 && s.out[0] == kMmaH0 && s.out[1] == kMmaH1 && s.out[2] == kMmaH2 && s.out[3] == 1;
}

// m-tiles of a tile's jets (two channels per m-tile).
YH_HD constexpr int mma_mtiles(int d, int order) { return (jet_channels(d, order) + 1) / 2; }
// m-tiles the per-warp buffers are sized for: the data jets' or the off-domain order-1 jets'.
YH_HD constexpr int mma_mtiles_max(int d, int order) {
  return mma_mtiles(d, order) > mma_mtiles(d, 1) ? mma_mtiles(d, order) : mma_mtiles(d, 1);
}
// Floats of shared memory per warp: slot1 (H1 wide), slot2 (H2), buf (max(H0, H1)).
YH_HD constexpr int mma_warp_floats(int d, int order) {
  return mma_mtiles_max(d, order) * 128 * (kMmaH1 / 8 + kMmaH2 / 8 + kMmaH1 / 8);
}
// Weight fragments, split, of layers 1 and 2, forward and transposed: 4 x 8 fragments of one
// float4 per lane.
inline constexpr int kMmaFragFloats = 4 * 8 * 32 * 4;

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
__device__ inline void mma3(float4& d, const Tf32x4& a, const float4& b) {
  const uint32_t b0b = __float_as_uint(b.x), b1b = __float_as_uint(b.y);
  const uint32_t b0s = __float_as_uint(b.z), b1s = __float_as_uint(b.w);
  mma_tf32(d, a.small, b0b, b1b);
  mma_tf32(d, a.big, b0s, b1s);
  mma_tf32(d, a.big, b0b, b1b);
}
__device__ inline void mma3(float4& d, const Tf32x4& a, uint32_t b0b, uint32_t b1b, uint32_t b0s, uint32_t b1s) {
  mma_tf32(d, a.small, b0b, b1b);
  mma_tf32(d, a.big, b0s, b1s);
  mma_tf32(d, a.big, b0b, b1b);
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

// ---- per-warp gradient partials (registers), Net-3 ----
template <int D>
struct MmaGrad {
  float4 dw1[2][2];  // dW1 [32 x 16]: m-tile (16 outs) x n-tile (8 ins), C fragments
  float4 dw2[1][4];  // dW2 [16 x 32]
  // Per lane, for its neurons n = 8 nt + 2t + e, q = 2 nt + e, summed over its points:
  float db1[8], db2[4], db0[4], dw0[4][D], dw3[4];
  float db3;
};
template <int D>
__device__ inline void zero(MmaGrad<D>& gr) {
  const float4 z4 = make_float4(0.f, 0.f, 0.f, 0.f);
  for (auto& r : gr.dw1)
    for (auto& f : r) f = z4;
  for (auto& f : gr.dw2[0]) f = z4;
  for (int q = 0; q < 8; ++q) gr.db1[q] = 0.f;
  for (int q = 0; q < 4; ++q) {
    gr.db2[q] = gr.db0[q] = gr.dw3[q] = 0.f;
    for (int i = 0; i < D; ++i) gr.dw0[q][i] = 0.f;
  }
  gr.db3 = 0.f;
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

// Channel c of the lane's neuron e (0: 2t, 1: 2t + 1) in the float4 of m-tile c / 2.
__device__ inline float& jet_comp(float4 (&q)[8], int c, int e) {
  float4& v = q[c >> 1];
  const int i = 2 * (c & 1) + e;
  return i == 0 ? v.x : i == 1 ? v.y : i == 2 ? v.z : v.w;
}

// ---- one tile ----
// The forward jets, losses and (when grad) the reverse pass of the points [begin, begin + np)
// (np <= 8) of a batch's data (OFF = false, jets of order O) or off-domain points (OFF = true,
// order O = 1), lane (g, t) working on point g. Adds the tile's gradient into gr and its loss
// terms into ls (lanes with t = 0 of valid points).
template <int D, int O, bool OFF, int MTB>
__device__ void mma_tile(const NetShape& s, const float* W, const float4* frag, const LossCfg& cfg,
                         const BatchSrc& src, float inv_m, float inv_k, int begin, int np, float4* slot1,
                         float4* slot2, float4* buf, bool grad, MmaGrad<D>& gr, Sums5& ls) {
  constexpr int C = jet_channels(D, O), MT = mma_mtiles(D, O);
  constexpr int NT1 = kMmaH1 / 8, NT2 = kMmaH2 / 8, NTB = kMmaH1 / 8;  // slot strides (neuron tiles)
  // Loops over m-tiles or neuron tiles unrolled by 2 at d = 2 (8 warps per SM, 255 registers
  // each: independent work per warp hides latency); not at d = 1 (16 warps, 128 registers).
  constexpr int U = D == 2 ? 2 : 1;
  const int lane = threadIdx.x & 31, g = lane >> 2, t = lane & 3, sl = lslot(lane);
  const bool valid = g < np;
  const float *W0 = W + s.woff[0], *b0 = W + s.boff[0], *W3 = W + s.woff[3];

  // Inputs of point g (zeros for the unused rows of a short tile: finite jets, zero adjoints).
  float x[D], aux[D], y = 0.f;  // aux: the data gradient g or the off-domain normal
#pragma unroll
  for (int i = 0; i < D; ++i) x[i] = aux[i] = 0.f;
  if (valid) {
    const int p = begin + g;
    if constexpr (!OFF) {
      const int i = src.idx ? src.idx[p] : p;
      y = src.y[i];
#pragma unroll
      for (int q = 0; q < D; ++q) {
        x[q] = src.x[size_t(i) * D + q];
        aux[q] = src.g[size_t(i) * D + q];
      }
    } else if (src.xo) {
#pragma unroll
      for (int q = 0; q < D; ++q) {
        x[q] = src.xo[size_t(p) * D + q];
        aux[q] = src.no[size_t(p) * D + q];
      }
    } else {
      offdomain_point<float>(D, src.okey, uint64_t(p), x, aux);
    }
  }

  // Layer 0 (z = W0 x + b0; channel 1 + i is W0's column i; zero above) and its sigmoid jet,
  // into buf as layer 1's input.
  auto layer0_z = [&](int n, float* z) {
    float acc = 0.f;
#pragma unroll
    for (int i = 0; i < D; ++i) acc = fmaf(W0[n * D + i], x[i], acc);
    z[0] = acc + b0[n];
#pragma unroll
    for (int c = 1; c < C; ++c) z[c] = (c <= D) ? W0[n * D + (c - 1)] : 0.f;
  };
#pragma unroll
  for (int nt = 0; nt < kMmaH0 / 8; ++nt) {
    float4 aq[8];
#pragma unroll
    for (int e = 0; e < 2; ++e) {
      float z[C], a[C];
      layer0_z(8 * nt + 2 * t + e, z);
      sigmoid_jet_point<D, O>(z, a, 1);
#pragma unroll
      for (int c = 0; c < 2 * MT; ++c) jet_comp(aq, c, e) = c < C ? a[c] : 0.f;
    }
#pragma unroll
    for (int mt = 0; mt < MT; ++mt) buf[(mt * NTB + nt) * 32 + sl] = aq[mt];
  }

  // The sigmoid jet of a layer's z (slot, NT neuron tiles) into buf.
  auto sigmoid_fwd = [&](const float4* slot, int nts, int snt) {
#pragma unroll(U)
    for (int nt = 0; nt < nts; ++nt) {
      float4 zq[8], aq[8];
#pragma unroll
      for (int mt = 0; mt < MT; ++mt) zq[mt] = slot[(mt * snt + nt) * 32 + sl];
#pragma unroll
      for (int e = 0; e < 2; ++e) {
        float z[C], a[C];
#pragma unroll
        for (int c = 0; c < C; ++c) z[c] = jet_comp(zq, c, e);
        sigmoid_jet_point<D, O>(z, a, 1);
#pragma unroll
        for (int c = 0; c < 2 * MT; ++c) jet_comp(aq, c, e) = c < C ? a[c] : 0.f;
      }
#pragma unroll
      for (int mt = 0; mt < MT; ++mt) buf[(mt * NTB + nt) * 32 + sl] = aq[mt];
    }
  };

  // Layer 1 (16 -> 32) and 2 (32 -> 16) on the tensor cores.
  mma_layer<MT, kMmaH0, kMmaH1, NTB, NT1, U>(buf, slot1, frag + 0 * 256, W + s.boff[1], lane);
  sigmoid_fwd(slot1, NT1, NT1);
  mma_layer<MT, kMmaH1, kMmaH2, NTB, NT2, U>(buf, slot2, frag + 2 * 256, W + s.boff[2], lane);

  // Layer 2's sigmoid jet (a2 into buf, for the reverse pass) and the output layer (16 -> 1):
  // the lane's partial sum over its 4 neurons, then over the quad (xor 1, 2; every lane of the
  // quad gets the same bits).
  float out[C];
#pragma unroll
  for (int c = 0; c < C; ++c) out[c] = 0.f;
#pragma unroll
  for (int nt = 0; nt < NT2; ++nt) {
    float4 zq[8], aq[8];
#pragma unroll
    for (int mt = 0; mt < MT; ++mt) zq[mt] = slot2[(mt * NT2 + nt) * 32 + sl];
#pragma unroll
    for (int e = 0; e < 2; ++e) {
      float z[C], a[C];
#pragma unroll
      for (int c = 0; c < C; ++c) z[c] = jet_comp(zq, c, e);
      sigmoid_jet_point<D, O>(z, a, 1);
      const float w = W3[8 * nt + 2 * t + e];
#pragma unroll
      for (int c = 0; c < C; ++c) out[c] = fmaf(w, a[c], out[c]);
#pragma unroll
      for (int c = 0; c < 2 * MT; ++c) jet_comp(aq, c, e) = c < C ? a[c] : 0.f;
    }
#pragma unroll
    for (int mt = 0; mt < MT; ++mt) buf[(mt * NTB + nt) * 32 + sl] = aq[mt];
  }
#pragma unroll
  for (int c = 0; c < C; ++c) {
    out[c] += __shfl_xor_sync(0xffffffffu, out[c], 1);
    out[c] += __shfl_xor_sync(0xffffffffu, out[c], 2);
  }
  out[0] += W[s.boff[3]];

  // Losses: the adjoint of the output jet (zero for unused rows).
  float dout[C];
#pragma unroll
  for (int c = 0; c < C; ++c) dout[c] = 0.f;
  if (valid) {
    if constexpr (!OFF) {
      const float wz = float(cfg.wz) * inv_m, wf = float(cfg.wf) * inv_m, wc = float(cfg.wc) * inv_m,
                  wx = float(cfg.wx) * inv_m;
      const PointLoss l = point_data_loss<D, O>(cfg, wz, wf, wc, wx, out, y, aux, dout);
      if (t == 0) ls.z += l.z, ls.f += l.f, ls.c += l.c, ls.x += l.x;
    } else {
      // cpu::strain_concentration_loss on one point (order-1 jet).
      const float ws = float(cfg.ws) * inv_k;
      float dot = 0.f;
#pragma unroll
      for (int i = 0; i < D; ++i) dot += out[1 + i] * aux[i];
#pragma unroll
      for (int i = 0; i < D; ++i) dout[1 + i] = dot < 0 ? ws * 2.f * dot * aux[i] : 0.f;
      if (t == 0 && dot < 0) ls.s += dot * dot;
    }
  }
  if (!grad) return;

  // ---- reverse pass ----
  // Output layer: dW3[n] += sum_c dout[c] a2[c][n], db3 += dout[0]; abar2 = W3[n] dout, then
  // layer 2's sigmoid jet reversed: zbar2 into slot2 (over z2), db2 += zbar2's channel 0.
  if (t == 0) gr.db3 += dout[0];
#pragma unroll
  for (int nt = 0; nt < NT2; ++nt) {
    float4 zq[8], aq[8], zbq[8];
#pragma unroll
    for (int mt = 0; mt < MT; ++mt) {
      zq[mt] = slot2[(mt * NT2 + nt) * 32 + sl];
      aq[mt] = buf[(mt * NTB + nt) * 32 + sl];
    }
#pragma unroll
    for (int e = 0; e < 2; ++e) {
      const int q = 2 * nt + e;
      float z[C], a[C], ab[C], zb[C];
#pragma unroll
      for (int c = 0; c < C; ++c) {
        z[c] = jet_comp(zq, c, e);
        a[c] = jet_comp(aq, c, e);
      }
      const float w = W3[8 * nt + 2 * t + e];
      float dw = 0.f;
#pragma unroll
      for (int c = 0; c < C; ++c) {
        dw = fmaf(dout[c], a[c], dw);
        ab[c] = w * dout[c];
      }
      gr.dw3[q] += dw;
      sigmoid_jet_point_backward<D, O>(z, a[0], ab, zb, 1);
      gr.db2[q] += zb[0];
#pragma unroll
      for (int c = 0; c < 2 * MT; ++c) jet_comp(zbq, c, e) = c < C ? zb[c] : 0.f;
    }
#pragma unroll
    for (int mt = 0; mt < MT; ++mt) slot2[(mt * NT2 + nt) * 32 + sl] = zbq[mt];
  }

  // abar1 = zbar2 W2 into buf; layer 1's sigmoid reversed: zbar1 into slot1 (over z1), the
  // recomputed a1 into buf (over abar1), db1.
  mma_layer<MT, kMmaH2, kMmaH1, NT2, NTB, U>(slot2, buf, frag + 3 * 256, nullptr, lane);
#pragma unroll(U)
  for (int nt = 0; nt < NT1; ++nt) {
    float4 zq[8], abq[8], aq[8], zbq[8];
#pragma unroll
    for (int mt = 0; mt < MT; ++mt) {
      zq[mt] = slot1[(mt * NT1 + nt) * 32 + sl];
      abq[mt] = buf[(mt * NTB + nt) * 32 + sl];
    }
#pragma unroll
    for (int e = 0; e < 2; ++e) {
      float z[C], a[C], ab[C], zb[C];
#pragma unroll
      for (int c = 0; c < C; ++c) {
        z[c] = jet_comp(zq, c, e);
        ab[c] = jet_comp(abq, c, e);
      }
      sigmoid_jet_point<D, O>(z, a, 1);
      sigmoid_jet_point_backward<D, O>(z, a[0], ab, zb, 1);
      if (nt == 0) gr.db1[e] += zb[0];
      if (nt == 1) gr.db1[2 + e] += zb[0];
      if (nt == 2) gr.db1[4 + e] += zb[0];
      if (nt == 3) gr.db1[6 + e] += zb[0];
#pragma unroll
      for (int c = 0; c < 2 * MT; ++c) {
        jet_comp(aq, c, e) = c < C ? a[c] : 0.f;
        jet_comp(zbq, c, e) = c < C ? zb[c] : 0.f;
      }
    }
#pragma unroll
    for (int mt = 0; mt < MT; ++mt) {
      slot1[(mt * NT1 + nt) * 32 + sl] = zbq[mt];
      buf[(mt * NTB + nt) * 32 + sl] = aq[mt];
    }
  }
  // dW2 += zbar2^T a1 (over the tile's rows).
  __syncwarp();
  mma_weight_grad<MT, kMmaH2, kMmaH1, NT2, NTB>(reinterpret_cast<const float*>(slot2),
                                                reinterpret_cast<const float*>(buf), gr.dw2, MT, lane);
  __syncwarp();

  // abar0 = zbar1 W1 into buf; layer 0's sigmoid reversed on the recomputed z0: its gradient
  // (dW0[n][i] += zbar0[0] x_i + zbar0[1 + i], db0 += zbar0[0]), and a0 into buf.
  mma_layer<MT, kMmaH1, kMmaH0, NT1, NTB, U>(slot1, buf, frag + 1 * 256, nullptr, lane);
#pragma unroll
  for (int nt = 0; nt < kMmaH0 / 8; ++nt) {
    float4 abq[8], aq[8];
#pragma unroll
    for (int mt = 0; mt < MT; ++mt) abq[mt] = buf[(mt * NTB + nt) * 32 + sl];
#pragma unroll
    for (int e = 0; e < 2; ++e) {
      const int q = 2 * nt + e;
      float z[C], a[C], ab[C], zb[C];
      layer0_z(8 * nt + 2 * t + e, z);
#pragma unroll
      for (int c = 0; c < C; ++c) ab[c] = jet_comp(abq, c, e);
      sigmoid_jet_point<D, O>(z, a, 1);
      sigmoid_jet_point_backward<D, O>(z, a[0], ab, zb, 1);
#pragma unroll
      for (int i = 0; i < D; ++i) {
        float v = zb[0] * x[i];
        if constexpr (O >= 1) v += zb[1 + i];
        gr.dw0[q][i] += v;
      }
      gr.db0[q] += zb[0];
#pragma unroll
      for (int c = 0; c < 2 * MT; ++c) jet_comp(aq, c, e) = c < C ? a[c] : 0.f;
    }
#pragma unroll
    for (int mt = 0; mt < MT; ++mt) buf[(mt * NTB + nt) * 32 + sl] = aq[mt];
  }
  // dW1 += zbar1^T a0.
  __syncwarp();
  mma_weight_grad<MT, kMmaH1, kMmaH0, NT1, NTB>(reinterpret_cast<const float*>(slot1),
                                                reinterpret_cast<const float*>(buf), gr.dw1, MT, lane);
  __syncwarp();
}

// Sum over the 8 points of a lane's quarter (lanes t, t + 4, ..., t + 28): xor 4, 8, 16.
__device__ inline float sum_over_points(float v) {
  v += __shfl_xor_sync(0xffffffffu, v, 4);
  v += __shfl_xor_sync(0xffffffffu, v, 8);
  v += __shfl_xor_sync(0xffffffffu, v, 16);
  return v;
}

// Writes a warp's gradient partials, complete over its lanes, to Gw[P] (shared memory).
template <int D>
__device__ inline void mma_write_grad(const NetShape& s, MmaGrad<D>& gr, float* Gw, int lane) {
  const int g = lane >> 2, t = lane & 3;
  auto put_frag = [&](const float4& f, int k, int out0, int in0) {
    const int in = s.in[k];
    float* Wk = Gw + s.woff[k];
    Wk[(out0 + g) * in + in0 + 2 * t] = f.x;
    Wk[(out0 + g) * in + in0 + 2 * t + 1] = f.y;
    Wk[(out0 + g + 8) * in + in0 + 2 * t] = f.z;
    Wk[(out0 + g + 8) * in + in0 + 2 * t + 1] = f.w;
  };
#pragma unroll
  for (int om = 0; om < 2; ++om)
#pragma unroll
    for (int nt = 0; nt < 2; ++nt) put_frag(gr.dw1[om][nt], 1, 16 * om, 8 * nt);
#pragma unroll
  for (int nt = 0; nt < 4; ++nt) put_frag(gr.dw2[0][nt], 2, 0, 8 * nt);
  // Per-neuron partials: lane (g, t) holds neurons 8 nt + 2t + e of its points.
#pragma unroll
  for (int q = 0; q < 8; ++q) {
    const float v = sum_over_points(gr.db1[q]);
    if (g == 0) Gw[s.boff[1] + 8 * (q >> 1) + 2 * t + (q & 1)] = v;
  }
#pragma unroll
  for (int q = 0; q < 4; ++q) {
    const int n = 8 * (q >> 1) + 2 * t + (q & 1);
    const float v2 = sum_over_points(gr.db2[q]), v0 = sum_over_points(gr.db0[q]), v3 = sum_over_points(gr.dw3[q]);
    float w0[D];
#pragma unroll
    for (int i = 0; i < D; ++i) w0[i] = sum_over_points(gr.dw0[q][i]);
    if (g == 0) {
      Gw[s.boff[2] + n] = v2;
      Gw[s.boff[0] + n] = v0;
      Gw[s.woff[3] + n] = v3;
#pragma unroll
      for (int i = 0; i < D; ++i) Gw[s.woff[0] + n * D + i] = w0[i];
    }
  }
  const float b3 = sum_over_points(gr.db3);  // non-zero on lanes t = 0 only
  if (lane == 0) Gw[s.boff[3]] = b3;
}

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
