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
//
// The MMA, the 3xTF32 split, the weights' fragments and the two kinds of product are in
// cuda/mma_tf32.cuh; this file holds the per-warp gradient, one tile's passes and the write-back.
#include <cstddef>
#include <cstdint>

#include "core/jet_layout.hpp"
#include "core/offdomain.hpp"
#include "cuda/batch_tasks.cuh"
#include "cuda/jet_shape.cuh"
#include "cuda/loss_jets.cuh"
#include "cuda/mma_tf32.cuh"
#include "cuda/sigmoid_jet.cuh"

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

// ---- one tile ----
// The pieces of mma_tile below, in the order it runs them. The lane (g, t) works on point g of
// the tile and on neurons 2t, 2t + 1 of every 8-wide neuron tile; sl is its slot (lslot).
// Slot strides in neuron tiles: slot1 NT1, slot2 NT2, buf NTB.
inline constexpr int kMmaNT1 = kMmaH1 / 8, kMmaNT2 = kMmaH2 / 8, kMmaNTB = kMmaH1 / 8;

// Inputs of point begin + g of the batch's data (OFF = false: x, the data gradient in aux, y) or
// off-domain points (OFF = true: x, the normal in aux); zeros when !valid (the unused rows of a
// short tile: finite jets, zero adjoints).
template <int D, bool OFF>
__device__ __forceinline__ void mma_tile_inputs(const BatchSrc& src, int begin, int g, bool valid, float (&x)[D],
                                                float (&aux)[D], float& y) {
  y = 0.f;
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
}

// Layer 0's pre-activation jet of neuron n at the lane's point: z = W0 x + b0; channel 1 + i is
// W0's column i; zero above.
template <int D, int C>
__device__ __forceinline__ void mma_layer0_z(const float* W0, const float* b0, const float (&x)[D], int n,
                                             float (&z)[C]) {
  float acc = 0.f;
#pragma unroll
  for (int i = 0; i < D; ++i) acc = fmaf(W0[n * D + i], x[i], acc);
  z[0] = acc + b0[n];
#pragma unroll
  for (int c = 1; c < C; ++c) z[c] = (c <= D) ? W0[n * D + (c - 1)] : 0.f;
}

// The sigmoid jet of neuron tile nt of a layer's z (slot, snt neuron tiles per row) into buf;
// each(e, a) sees the activation jet a[C] of the lane's neuron e before it is stored.
template <int D, int O, int MT, class Each>
__device__ __forceinline__ void mma_sigmoid_tile(const float4* slot, int snt, int nt, float4* buf, int sl,
                                                 Each&& each) {
  constexpr int C = jet_channels(D, O);
  float4 zq[8], aq[8];
  load_jet_tiles<MT>(zq, slot, snt, nt, sl);
#pragma unroll
  for (int e = 0; e < 2; ++e) {
    float z[C], a[C];
    get_jet<C>(zq, e, z);
    sigmoid_jet_point<D, O>(z, a, 1);
    each(e, a);
    put_jet<C, MT>(aq, e, a);
  }
  store_jet_tiles<MT>(aq, buf, kMmaNTB, nt, sl);
}

// The forward jets of the tile: layer 0 and its sigmoid jet into buf as layer 1's input, layers
// 1 (16 -> 32) and 2 (32 -> 16) on the tensor cores (z1 into slot1, z2 into slot2), layer 2's
// sigmoid jet (a2 into buf, for the reverse pass) and the output layer (16 -> 1): out[C], the
// lane's partial sum over its 4 neurons, then over the quad (xor 1, 2; every lane of the quad
// gets the same bits).
template <int D, int O, int MT, int U>
__device__ __forceinline__ void mma_tile_forward(const NetShape& s, const float* W, const float* W0, const float* b0,
                                                 const float* W3, const float4* frag, const float (&x)[D],
                                                 float4* slot1, float4* slot2, float4* buf, int lane,
                                                 float (&out)[jet_channels(D, O)]) {
  constexpr int C = jet_channels(D, O);
  const int t = lane & 3, sl = lslot(lane);
#pragma unroll
  for (int nt = 0; nt < kMmaH0 / 8; ++nt) {
    float4 aq[8];
#pragma unroll
    for (int e = 0; e < 2; ++e) {
      float z[C], a[C];
      mma_layer0_z<D, C>(W0, b0, x, 8 * nt + 2 * t + e, z);
      sigmoid_jet_point<D, O>(z, a, 1);
      put_jet<C, MT>(aq, e, a);
    }
    store_jet_tiles<MT>(aq, buf, kMmaNTB, nt, sl);
  }

  mma_layer<MT, kMmaH0, kMmaH1, kMmaNTB, kMmaNT1, U>(buf, slot1, frag + 0 * 256, W + s.boff[1], lane);
#pragma unroll(U)
  for (int nt = 0; nt < kMmaNT1; ++nt) mma_sigmoid_tile<D, O, MT>(slot1, kMmaNT1, nt, buf, sl, [](int, const float*) {});
  mma_layer<MT, kMmaH1, kMmaH2, kMmaNTB, kMmaNT2, U>(buf, slot2, frag + 2 * 256, W + s.boff[2], lane);

#pragma unroll
  for (int c = 0; c < C; ++c) out[c] = 0.f;
#pragma unroll
  for (int nt = 0; nt < kMmaNT2; ++nt)
    mma_sigmoid_tile<D, O, MT>(slot2, kMmaNT2, nt, buf, sl, [&](int e, const float* a) {
      const float w = W3[8 * nt + 2 * t + e];
#pragma unroll
      for (int c = 0; c < C; ++c) out[c] = fmaf(w, a[c], out[c]);
    });
#pragma unroll
  for (int c = 0; c < C; ++c) {
    out[c] += __shfl_xor_sync(0xffffffffu, out[c], 1);
    out[c] += __shfl_xor_sync(0xffffffffu, out[c], 2);
  }
  out[0] += W[s.boff[3]];
}

// Losses of the lane's point: the adjoint of the output jet dout[C] (zero for unused rows), the
// loss terms added into ls by the lanes with t = 0.
template <int D, int O, bool OFF>
__device__ __forceinline__ void mma_tile_losses(const LossCfg& cfg, float inv_m, float inv_k, bool valid, int t,
                                                float y, const float (&aux)[D],
                                                const float (&out)[jet_channels(D, O)],
                                                float (&dout)[jet_channels(D, O)], Sums5& ls) {
  constexpr int C = jet_channels(D, O);
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
}

// Reverse of the output layer: dW3[n] += sum_c dout[c] a2[c][n], db3 += dout[0]; abar2 = W3[n]
// dout, then layer 2's sigmoid jet reversed: zbar2 into slot2 (over z2), db2 += zbar2's
// channel 0.
template <int D, int O, int MT>
__device__ __forceinline__ void mma_output_reverse(const float* W3, const float (&dout)[jet_channels(D, O)],
                                                   float4* slot2, const float4* buf, int lane, MmaGrad<D>& gr) {
  constexpr int C = jet_channels(D, O);
  const int t = lane & 3, sl = lslot(lane);
  if (t == 0) gr.db3 += dout[0];
#pragma unroll
  for (int nt = 0; nt < kMmaNT2; ++nt) {
    float4 zq[8], aq[8], zbq[8];
    load_jet_tiles<MT>(zq, slot2, kMmaNT2, aq, buf, kMmaNTB, nt, sl);
#pragma unroll
    for (int e = 0; e < 2; ++e) {
      const int q = 2 * nt + e;
      float z[C], a[C], ab[C], zb[C];
      get_jet<C>(zq, aq, e, z, a);
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
      put_jet<C, MT>(zbq, e, zb);
    }
    store_jet_tiles<MT>(zbq, slot2, kMmaNT2, nt, sl);
  }
}

// abar1 = zbar2 W2 into buf; layer 1's sigmoid reversed: zbar1 into slot1 (over z1), the
// recomputed a1 into buf (over abar1), db1; then dW2 += zbar2^T a1 (over the tile's rows).
template <int D, int O, int MT, int U>
__device__ __forceinline__ void mma_layer1_reverse(const float4* frag, float4* slot1, float4* slot2, float4* buf,
                                                   int lane, MmaGrad<D>& gr) {
  constexpr int C = jet_channels(D, O);
  const int sl = lslot(lane);
  mma_layer<MT, kMmaH2, kMmaH1, kMmaNT2, kMmaNTB, U>(slot2, buf, frag + 3 * 256, nullptr, lane);
#pragma unroll(U)
  for (int nt = 0; nt < kMmaNT1; ++nt) {
    float4 zq[8], abq[8], aq[8], zbq[8];
    load_jet_tiles<MT>(zq, slot1, kMmaNT1, abq, buf, kMmaNTB, nt, sl);
#pragma unroll
    for (int e = 0; e < 2; ++e) {
      float z[C], a[C], ab[C], zb[C];
      get_jet<C>(zq, abq, e, z, ab);
      sigmoid_jet_point<D, O>(z, a, 1);
      sigmoid_jet_point_backward<D, O>(z, a[0], ab, zb, 1);
      // db1 of neuron 8 nt + 2t + e: nt is not a compile-time index where the loop is not
      // fully unrolled, so every entry is written, the one of nt with zb[0] added (as selects).
#pragma unroll
      for (int k = 0; k < kMmaNT1; ++k) gr.db1[2 * k + e] = nt == k ? gr.db1[2 * k + e] + zb[0] : gr.db1[2 * k + e];
      put_jet<C, MT>(aq, zbq, e, a, zb);
    }
    store_jet_tiles<MT>(zbq, slot1, kMmaNT1, aq, buf, kMmaNTB, nt, sl);
  }
  mma_weight_grad_synced<MT, kMmaH2, kMmaH1, kMmaNT2, kMmaNTB>(slot2, buf, gr.dw2, lane);
}

// abar0 = zbar1 W1 into buf; layer 0's sigmoid reversed on the recomputed z0: its gradient
// (dW0[n][i] += zbar0[0] x_i + zbar0[1 + i], db0 += zbar0[0]), and a0 into buf; then
// dW1 += zbar1^T a0.
template <int D, int O, int MT, int U>
__device__ __forceinline__ void mma_layer0_reverse(const float* W0, const float* b0, const float4* frag,
                                                   const float (&x)[D], float4* slot1, float4* buf, int lane,
                                                   MmaGrad<D>& gr) {
  constexpr int C = jet_channels(D, O);
  const int t = lane & 3, sl = lslot(lane);
  mma_layer<MT, kMmaH1, kMmaH0, kMmaNT1, kMmaNTB, U>(slot1, buf, frag + 1 * 256, nullptr, lane);
#pragma unroll
  for (int nt = 0; nt < kMmaH0 / 8; ++nt) {
    float4 abq[8], aq[8];
    load_jet_tiles<MT>(abq, buf, kMmaNTB, nt, sl);
#pragma unroll
    for (int e = 0; e < 2; ++e) {
      const int q = 2 * nt + e;
      float z[C], a[C], ab[C], zb[C];
      mma_layer0_z<D, C>(W0, b0, x, 8 * nt + 2 * t + e, z);
      get_jet<C>(abq, e, ab);
      sigmoid_jet_point<D, O>(z, a, 1);
      sigmoid_jet_point_backward<D, O>(z, a[0], ab, zb, 1);
#pragma unroll
      for (int i = 0; i < D; ++i) {
        float v = zb[0] * x[i];
        if constexpr (O >= 1) v += zb[1 + i];
        gr.dw0[q][i] += v;
      }
      gr.db0[q] += zb[0];
      put_jet<C, MT>(aq, e, a);
    }
    store_jet_tiles<MT>(aq, buf, kMmaNTB, nt, sl);
  }
  mma_weight_grad_synced<MT, kMmaH1, kMmaH0, kMmaNT1, kMmaNTB>(slot1, buf, gr.dw1, lane);
}

// The forward jets, losses and (when grad) the reverse pass of the points [begin, begin + np)
// (np <= 8) of a batch's data (OFF = false, jets of order O) or off-domain points (OFF = true,
// order O = 1), lane (g, t) working on point g. Adds the tile's gradient into gr and its loss
// terms into ls (lanes with t = 0 of valid points).
template <int D, int O, bool OFF, int MTB>
__device__ void mma_tile(const NetShape& s, const float* W, const float4* frag, const LossCfg& cfg,
                         const BatchSrc& src, float inv_m, float inv_k, int begin, int np, float4* slot1,
                         float4* slot2, float4* buf, bool grad, MmaGrad<D>& gr, Sums5& ls) {
  constexpr int C = jet_channels(D, O), MT = mma_mtiles(D, O);
  // Loops over m-tiles or neuron tiles unrolled by 2 at d = 2 (8 warps per SM, 255 registers
  // each: independent work per warp hides latency); not at d = 1 (16 warps, 128 registers).
  constexpr int U = D == 2 ? 2 : 1;
  const int lane = threadIdx.x & 31, g = lane >> 2, t = lane & 3;
  const bool valid = g < np;
  const float *W0 = W + s.woff[0], *b0 = W + s.boff[0], *W3 = W + s.woff[3];

  float x[D], aux[D], y;  // aux: the data gradient g or the off-domain normal
  mma_tile_inputs<D, OFF>(src, begin, g, valid, x, aux, y);
  float out[C], dout[C];
  mma_tile_forward<D, O, MT, U>(s, W, W0, b0, W3, frag, x, slot1, slot2, buf, lane, out);
  mma_tile_losses<D, O, OFF>(cfg, inv_m, inv_k, valid, t, y, aux, out, dout, ls);
  if (!grad) return;

  // ---- reverse pass ----
  mma_output_reverse<D, O, MT>(W3, dout, slot2, buf, lane, gr);
  mma_layer1_reverse<D, O, MT, U>(frag, slot1, slot2, buf, lane, gr);
  mma_layer0_reverse<D, O, MT, U>(W0, b0, frag, x, slot1, buf, lane, gr);
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
