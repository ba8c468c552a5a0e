#pragma once
// The polish's loss on the device (train/cuda_polish.cu): the twin of cpu::mlp_loss_grad as the
// default recipe's polish calls it, i.e. the data losses w_Z L_Z + w_F L_F with per-point
// weights (the relative fit, train/polish.hpp) on first-order jets, and the 1D rest-curvature
// penalty on one second-order jet. Templated on the compute type T (float or double: the CPU
// polish computes the 1D terms in double, the 2D terms in float) and on the input dimension D.
//
// One thread block runs a chunk of NP points entirely in shared memory. With C = D + 1
// channels, a hidden neuron's first-order jet at a point is
//     a = s0(z),   a_i = s1 z_i            (s1 = s0 (1 - s0))
// and its reverse, from the adjoints (abar, abar_i) of a hidden neuron's outputs,
//     zbar   = abar s1 + sum_i abar_i s2 z_i       (s2 = s1 (1 - 2 s0))
//     zbar_i = abar_i s1
// (cpu/sigmoid_jet.hpp at order 1). A linear layer maps every channel by the same W; the bias
// enters the value channel only; the first layer's input jet is (x, e_1, ..., e_D).
//
// Layout of a chunk: a hidden layer's jets are [n][RS] with channel c of point p at c*NP + p and
// RS = C*NP + 1 (odd, so that the weight gradient's threads, which walk down the neurons, hit
// distinct banks); the input derivatives z_i of the pre-activations [n][D*NP] (the reverse
// needs them). Determinism: each parameter's gradient over a chunk is summed by one thread over
// the points and channels in a fixed order, and added by that thread into the block's gradient
// chunk after chunk; the loss terms are summed by thread 0 in point order. No atomics.
#include <cstddef>

#include "cuda/jet_shape.cuh"

namespace yarnhom::cuda::detail {

// Points per chunk: float 64 (as the CPU's kLossChunk), double 32.
template <class T>
YH_HD constexpr int polish_np() {
  return sizeof(T) == 4 ? 64 : 32;
}

// Offsets (in T) of a chunk's buffers within a block's shared memory, after `base`.
struct PolishLayout {
  int RS, w, g0, g1, act, zin, bufA, bufB, out, x, y, g, wt, lz, lf, rest, sums, total;
};
template <class T>
YH_HD inline PolishLayout polish_layout(const NetShape& s) {
  constexpr int NP = polish_np<T>();
  const int C = s.d + 1, P4 = (s.P + 3) & ~3;
  PolishLayout l;
  l.RS = C * NP + 1;
  int o = 0;
  auto take = [&](int n) {
    const int at = o;
    o += (n + 3) & ~3;
    return at;
  };
  l.w = take(P4);
  l.g0 = take(P4);
  l.g1 = take(P4);
  l.act = take(s.hsum * l.RS);
  l.zin = take(s.hsum * s.d * NP);
  l.bufA = take(s.hmax * l.RS);
  l.bufB = take(s.hmax * l.RS);
  l.out = take(l.RS);
  l.x = take(NP * s.d);
  l.y = take(NP);
  l.g = take(NP * s.d);
  l.wt = take(NP);
  l.lz = take(NP);
  l.lf = take(NP);
  l.rest = take(6 * s.hsum + 6 * s.hmax + 4);
  l.sums = take(2 * 4);  // per parity: z, f (T), and the penalty (T)
  l.total = o;
  return l;
}

#ifdef __CUDACC__

template <class T>
__device__ inline T sigmoid_value(T z);
template <>
__device__ inline float sigmoid_value<float>(float z) {
  return 1.f / (1.f + expf(-z));
}
template <>
__device__ inline double sigmoid_value<double>(double z) {
  return 1.0 / (1.0 + exp(-z));
}

// sum_{p < np} a[p] b[p] and sum_{p < np} a[p] with four interleaved partial sums (p mod 4)
// added in a fixed order: four independent chains of FMAs instead of one (the weight gradient's
// sums over a chunk were the longest dependency chains of an evaluation).
template <class T>
__device__ inline T dot4(const T* a, const T* b, int np) {
  T s0 = T(0), s1 = T(0), s2 = T(0), s3 = T(0);
  int p = 0;
  for (; p + 4 <= np; p += 4) {
    s0 += a[p] * b[p];
    s1 += a[p + 1] * b[p + 1];
    s2 += a[p + 2] * b[p + 2];
    s3 += a[p + 3] * b[p + 3];
  }
  for (; p < np; ++p) s0 += a[p] * b[p];
  return (s0 + s1) + (s2 + s3);
}
template <class T>
__device__ inline T sum4(const T* a, int np) {
  T s0 = T(0), s1 = T(0), s2 = T(0), s3 = T(0);
  int p = 0;
  for (; p + 4 <= np; p += 4) {
    s0 += a[p];
    s1 += a[p + 1];
    s2 += a[p + 2];
    s3 += a[p + 3];
  }
  for (; p < np; ++p) s0 += a[p];
  return (s0 + s1) + (s2 + s3);
}

// Pointers of one block's chunk buffers.
template <class T>
struct PolishChunk {
  T *act, *zin, *bufA, *bufB, *out, *x, *y, *g, *wt, *lz, *lf, *rest;
  int RS;
};
template <class T>
__device__ inline PolishChunk<T> make_polish_chunk(T* sm, const PolishLayout& l) {
  return PolishChunk<T>{sm + l.act, sm + l.zin, sm + l.bufA, sm + l.bufB, sm + l.out, sm + l.x, sm + l.y,
                        sm + l.g,   sm + l.wt,  sm + l.lz,   sm + l.lf,   sm + l.rest, l.RS};
}

// Forward pass of the np points in ch.x: the output jet in ch.out[c*NP + p].
template <class T, int D>
__device__ void polish_chunk_forward(const NetShape& s, const T* W, int np, const PolishChunk<T>& ch) {
  constexpr int C = D + 1, NP = polish_np<T>();
  const int RS = ch.RS;
  {  // layer 0: z = W x + b, z_i = W[:, i]
    const int n = s.out[0];
    const T* W0 = W + s.woff[0];
    const T* b0 = W + s.boff[0];
    for (int t = threadIdx.x; t < n * np; t += blockDim.x) {
      const int r = t / np, p = t % np;
      T z = T(0);
#pragma unroll
      for (int i = 0; i < D; ++i) z += W0[r * D + i] * ch.x[p * D + i];
      z += b0[r];
      const T s0 = sigmoid_value<T>(z), s1 = s0 * (T(1) - s0);
      T* a = ch.act + size_t(s.hoff[0] + r) * RS;
      T* zi = ch.zin + size_t(s.hoff[0] + r) * D * NP;
      a[p] = s0;
#pragma unroll
      for (int i = 0; i < D; ++i) {
        zi[i * NP + p] = W0[r * D + i];
        a[(1 + i) * NP + p] = s1 * W0[r * D + i];
      }
    }
  }
  __syncthreads();
  for (int k = 1; k < s.L; ++k) {
    const int n = s.out[k], m = s.in[k];
    const T* Wk = W + s.woff[k];
    const T* A = ch.act + size_t(s.hoff[k - 1]) * RS;
    const bool last = k == s.L - 1;
    for (int t = threadIdx.x; t < n * np; t += blockDim.x) {
      const int r = t / np, p = t % np;
      T z[C], z2[C];  // even and odd j: two independent chains per channel
#pragma unroll
      for (int c = 0; c < C; ++c) z[c] = z2[c] = T(0);
      const T* wr = Wk + r * m;
      int j = 0;
      for (; j + 2 <= m; j += 2) {
        const T w0 = wr[j], w1 = wr[j + 1];
        const T* a0 = A + size_t(j) * RS + p;
        const T* a1 = a0 + RS;
#pragma unroll
        for (int c = 0; c < C; ++c) {
          z[c] += w0 * a0[c * NP];
          z2[c] += w1 * a1[c * NP];
        }
      }
      if (j < m) {
        const T* a0 = A + size_t(j) * RS + p;
#pragma unroll
        for (int c = 0; c < C; ++c) z[c] += wr[j] * a0[c * NP];
      }
#pragma unroll
      for (int c = 0; c < C; ++c) z[c] += z2[c];
      z[0] += W[s.boff[k] + r];
      if (last) {
#pragma unroll
        for (int c = 0; c < C; ++c) ch.out[c * NP + p] = z[c];
      } else {
        const T s0 = sigmoid_value<T>(z[0]), s1 = s0 * (T(1) - s0);
        T* a = ch.act + size_t(s.hoff[k] + r) * RS;
        T* zi = ch.zin + size_t(s.hoff[k] + r) * D * NP;
        a[p] = s0;
#pragma unroll
        for (int i = 0; i < D; ++i) {
          zi[i * NP + p] = z[1 + i];
          a[(1 + i) * NP + p] = s1 * z[1 + i];
        }
      }
    }
    __syncthreads();
  }
}

// The data losses of the chunk (cpu::data_losses with L_Z and L_F): per point
// k (yhat - y)^2 and k |grad yhat - g|^2 (k the point's weight), summed by thread 0 in point
// order into sum[0], sum[1]; with grad, ch.out becomes the adjoint (wz, wf: weight x 1/M).
template <class T, int D>
__device__ void polish_chunk_losses(int np, const PolishChunk<T>& ch, T wz, T wf, bool use_z, bool use_f,
                                    bool grad, T* sum) {
  constexpr int NP = polish_np<T>();
  for (int p = threadIdx.x; p < np; p += blockDim.x) {
    const T k = ch.wt[p];
    T lz = T(0), lf = T(0);
    if (use_z) {
      const T r = ch.out[p] - ch.y[p];
      lz = k * r * r;
      ch.out[p] = grad ? wz * T(2) * k * r : T(0);
    } else {
      ch.out[p] = T(0);
    }
#pragma unroll
    for (int i = 0; i < D; ++i) {
      T& o = ch.out[(1 + i) * NP + p];
      if (use_f) {
        const T r = o - ch.g[p * D + i];
        lf += k * r * r;
        o = grad ? wf * T(2) * k * r : T(0);
      } else {
        o = T(0);
      }
    }
    ch.lz[p] = lz;
    ch.lf[p] = lf;
  }
  __syncthreads();
  if (threadIdx.x == 0) {
    T z = T(0), f = T(0);
    z = sum4(ch.lz, np);
    f = sum4(ch.lf, np);
    sum[0] += z;
    sum[1] += f;
  }
}

// The reverse pass of the chunk from the adjoint in ch.out: its parameter gradient added into G
// (shared) by the thread that owns each parameter. Needs polish_chunk_forward's buffers.
template <class T, int D>
__device__ void polish_chunk_backward(const NetShape& s, const T* W, int np, const PolishChunk<T>& ch, T* G) {
  constexpr int C = D + 1, NP = polish_np<T>();
  const int RS = ch.RS;
  const T* zbar = ch.out;  // adjoint of layer k's pre-activation jets, [out_k][RS]
  T* bufs[2] = {ch.bufA, ch.bufB};
  int which = 0;
  for (int k = s.L - 1; k >= 1; --k) {
    const int n = s.out[k], m = s.in[k];
    const T* A = ch.act + size_t(s.hoff[k - 1]) * RS;
    const T* Wk = W + s.woff[k];
    // dW[r][j] = sum_c sum_p zbar[r][c][p] a[j][c][p]; db[r] = sum_p zbar[r][0][p].
    for (int t = threadIdx.x; t < n * (m + 1); t += blockDim.x) {
      const int r = t / (m + 1), j = t % (m + 1);
      const T* zr = zbar + size_t(r) * RS;
      T acc = T(0);
      if (j < m) {
        const T* aj = A + size_t(j) * RS;
#pragma unroll
        for (int c = 0; c < C; ++c) acc += dot4(zr + c * NP, aj + c * NP, np);
        G[s.woff[k] + r * m + j] += acc;
      } else {
        acc = sum4(zr, np);
        G[s.boff[k] + r] += acc;
      }
    }
    // abar[j][c][p] = sum_r W[r][j] zbar[r][c][p], then the sigmoid's reverse into zbar of
    // hidden layer k-1 (a different buffer from the one being read).
    T* nz = bufs[which];
    which ^= 1;
    for (int t = threadIdx.x; t < m * np; t += blockDim.x) {
      const int j = t / np, p = t % np;
      T ab[C], ab2[C];  // even and odd r
#pragma unroll
      for (int c = 0; c < C; ++c) ab[c] = ab2[c] = T(0);
      int r = 0;
      for (; r + 2 <= n; r += 2) {
        const T w0 = Wk[r * m + j], w1 = Wk[(r + 1) * m + j];
        const T* z0 = zbar + size_t(r) * RS + p;
        const T* z1 = z0 + RS;
#pragma unroll
        for (int c = 0; c < C; ++c) {
          ab[c] += w0 * z0[c * NP];
          ab2[c] += w1 * z1[c * NP];
        }
      }
      if (r < n) {
        const T* z0 = zbar + size_t(r) * RS + p;
#pragma unroll
        for (int c = 0; c < C; ++c) ab[c] += Wk[r * m + j] * z0[c * NP];
      }
#pragma unroll
      for (int c = 0; c < C; ++c) ab[c] += ab2[c];
      const T s0 = A[size_t(j) * RS + p];
      const T s1 = s0 * (T(1) - s0), s2 = s1 * (T(1) - T(2) * s0);
      const T* zi = ch.zin + size_t(s.hoff[k - 1] + j) * D * NP;
      T zb0 = ab[0] * s1;
#pragma unroll
      for (int i = 0; i < D; ++i) zb0 += ab[1 + i] * s2 * zi[i * NP + p];
      T* o = nz + size_t(j) * RS + p;
      o[0] = zb0;
#pragma unroll
      for (int i = 0; i < D; ++i) o[(1 + i) * NP] = ab[1 + i] * s1;
    }
    __syncthreads();
    zbar = nz;
  }
  // Layer 0: dW0[r][i] = sum_p zbar[r][0][p] x[p][i] + sum_p zbar[r][1+i][p]; db0[r] = sum_p zbar[r][0][p].
  const int n = s.out[0];
  for (int t = threadIdx.x; t < n * (D + 1); t += blockDim.x) {
    const int r = t / (D + 1), i = t % (D + 1);
    const T* zr = zbar + size_t(r) * RS;
    T acc = T(0);
    if (i < D) {
      for (int p = 0; p < np; ++p) acc += zr[p] * ch.x[p * D + i];
      acc += sum4(zr + (1 + i) * NP, np);
      G[s.woff[0] + r * D + i] += acc;
    } else {
      acc = sum4(zr, np);
      G[s.boff[0] + r] += acc;
    }
  }
  __syncthreads();
}

// The rest-curvature penalty of a 1D network, w (y''(x_r) - k)^2, on one second-order jet
// (v, v', v'') computed by the block with one thread per neuron; with G, its gradient is added
// into G. Forward of a hidden neuron:
//     a = s0,  a' = s1 z',  a'' = s2 z'^2 + s1 z''
// reverse (s3 = s1 (1 - 6 s0 + 6 s0^2)):
//     zbar   = abar s1 + abar' s2 z' + abar'' (s3 z'^2 + s2 z'')
//     zbar'  = abar' s1 + 2 abar'' s2 z'
//     zbar'' = abar'' s1
// Returns the penalty (every thread). buf: the chunk's `rest` region.
template <class T>
__device__ double polish_rest_penalty_1d(const NetShape& s, const T* W, T xr, double k, double w, T* G, T* buf) {
  T* Z = buf;                 // [hsum][3]: z, z', z''
  T* A = buf + 3 * s.hsum;    // [hsum][3]: a, a', a''
  T* B0 = A + 3 * s.hsum;     // [hmax][3]
  T* B1 = B0 + 3 * s.hmax;    // [hmax][3]
  T* out = B1 + 3 * s.hmax;   // [3]
  auto act = [&](int h, T z0, T z1, T z2) {
    const T s0 = sigmoid_value<T>(z0), s1 = s0 * (T(1) - s0), s2 = s1 * (T(1) - T(2) * s0);
    Z[3 * h] = z0, Z[3 * h + 1] = z1, Z[3 * h + 2] = z2;
    A[3 * h] = s0, A[3 * h + 1] = s1 * z1, A[3 * h + 2] = s2 * z1 * z1 + s1 * z2;
  };
  for (int r = threadIdx.x; r < s.out[0]; r += blockDim.x)
    act(s.hoff[0] + r, W[s.woff[0] + r] * xr + W[s.boff[0] + r], W[s.woff[0] + r], T(0));
  __syncthreads();
  for (int k2 = 1; k2 < s.L; ++k2) {
    const int n = s.out[k2], m = s.in[k2];
    for (int r = threadIdx.x; r < n; r += blockDim.x) {
      T z[3] = {T(0), T(0), T(0)};
      for (int j = 0; j < m; ++j) {
        const T wv = W[s.woff[k2] + r * m + j];
        const T* a = A + 3 * (s.hoff[k2 - 1] + j);
        z[0] += wv * a[0], z[1] += wv * a[1], z[2] += wv * a[2];
      }
      z[0] += W[s.boff[k2] + r];
      if (k2 == s.L - 1) out[0] = z[0], out[1] = z[1], out[2] = z[2];
      else act(s.hoff[k2] + r, z[0], z[1], z[2]);
    }
    __syncthreads();
  }
  const double res = double(out[2]) - k;
  const double pen = w * res * res;
  if (!G) {
    __syncthreads();
    return pen;
  }
  const T d2 = T(2 * w * res);
  __syncthreads();
  if (threadIdx.x == 0) B1[0] = T(0), B1[1] = T(0), B1[2] = d2;  // the output's adjoint
  __syncthreads();
  const T* zbar = B1;
  T* bufs[2] = {B0, B1};
  int which = 0;
  for (int k2 = s.L - 1; k2 >= 1; --k2) {
    const int n = s.out[k2], m = s.in[k2];
    for (int t = threadIdx.x; t < n * (m + 1); t += blockDim.x) {
      const int r = t / (m + 1), j = t % (m + 1);
      if (j < m) {
        const T* a = A + 3 * (s.hoff[k2 - 1] + j);
        G[s.woff[k2] + r * m + j] += zbar[3 * r] * a[0] + zbar[3 * r + 1] * a[1] + zbar[3 * r + 2] * a[2];
      } else {
        G[s.boff[k2] + r] += zbar[3 * r];
      }
    }
    // The output's adjoint sits in B1 while B0 is written; then B1, B0, ... alternate.
    T* nz = bufs[which];
    which ^= 1;
    __syncthreads();  // (nz may be the buffer an earlier layer's adjoint was read from)
    for (int j = threadIdx.x; j < m; j += blockDim.x) {
      T ab[3] = {T(0), T(0), T(0)};
      for (int r = 0; r < n; ++r) {
        const T wv = W[s.woff[k2] + r * m + j];
        ab[0] += wv * zbar[3 * r], ab[1] += wv * zbar[3 * r + 1], ab[2] += wv * zbar[3 * r + 2];
      }
      const int h = s.hoff[k2 - 1] + j;
      const T s0 = A[3 * h], s1 = s0 * (T(1) - s0), s2 = s1 * (T(1) - T(2) * s0);
      const T s3 = s1 * (T(1) - T(6) * s0 + T(6) * s0 * s0);
      const T z1 = Z[3 * h + 1], z2 = Z[3 * h + 2];
      nz[3 * j] = ab[0] * s1 + ab[1] * s2 * z1 + ab[2] * (s3 * z1 * z1 + s2 * z2);
      nz[3 * j + 1] = ab[1] * s1 + T(2) * ab[2] * s2 * z1;
      nz[3 * j + 2] = ab[2] * s1;
    }
    __syncthreads();
    zbar = nz;
  }
  for (int r = threadIdx.x; r < s.out[0]; r += blockDim.x) {
    G[s.woff[0] + r] += zbar[3 * r] * xr + zbar[3 * r + 1];
    G[s.boff[0] + r] += zbar[3 * r];
  }
  __syncthreads();
  return pen;
}

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
