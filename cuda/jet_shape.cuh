#pragma once
// The shapes the block-level building blocks (cuda/jet_block.cuh) work on: a network's shape as
// kernels take it, the loss configuration, the loss sums, and the shared-memory layout of a
// chunk of points (a layer's jet is [n, S] with channel c of point p in column c*np + p).
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "core/jet_layout.hpp"
#include "core/network.hpp"

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

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
