#include "cpu/polish_kernel.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <utility>

#include "cpu/simd_block.hpp"

namespace yarnhom::cpu {
namespace {

using simd::Simd;
using simd::unroll;

constexpr int max_of(std::initializer_list<int> l) {
  int m = 0;
  for (int v : l) m = v > m ? v : m;
  return m;
}

// A group of G x L points into SIMD lanes (both kernels below): targets Y and weights K ([G],
// weight 1 where the batch has none), inputs X and target gradients Gd ([D][G]); the lanes past
// the batch's m points carry zero weight and zero inputs.
template <class T, int D, int G, int L, class V>
inline void load_group(const LossBatch<T>& batch, int p0, V* X, V* Gd, V* Y, V* K) {
  const int m = batch.m;
  for (int g = 0; g < G; ++g)
    for (int l = 0; l < L; ++l) {
      const int p = p0 + g * L + l;
      const bool in = p < m;
      Y[g][l] = in ? batch.y[p] : T(0);
      K[g][l] = in ? (batch.wt ? batch.wt[p] : T(1)) : T(0);
      for (int j = 0; j < D; ++j) {
        X[j * G + g][l] = in ? batch.x[size_t(p) * D + j] : T(0);
        Gd[j * G + g][l] = in ? batch.g[size_t(p) * D + j] : T(0);
      }
    }
}

// The losses from the lane sums sz, sf (sum over points of the weighted squared errors) and,
// with grad, the gradient from the P lane accumulators dw (both kernels below).
template <class T, int L, class V>
inline LossValues lane_totals(const V& sz, const V& sf, T inv_m, const LossWeights& w, const V* dw, int P, T* grad) {
  LossValues v;
  T tz = 0, tf = 0;
  for (int l = 0; l < L; ++l) tz += sz[l], tf += sf[l];
  v.z = double(tz) * double(inv_m);
  v.f = double(tf) * double(inv_m);
  v.total = w.z * v.z + w.f * v.f;
  if (grad)
    for (int p = 0; p < P; ++p) {
      T s = 0;
      for (int l = 0; l < L; ++l) s += dw[p][l];
      grad[p] = s;
    }
  return v;
}

// One network shape: input dimension D, hidden widths H..., a linear output; jets of order 1
// (C = 1 + D channels: the value and the D input derivatives).
template <class T, int D, int... H>
struct Fused {
  using V = typename Simd<T>::V;
  static constexpr int L = Simd<T>::L;  // points per vector
  static constexpr int G = 2;           // vectors of points per group
  static constexpr int C = 1 + D;
  static constexpr int NL = int(sizeof...(H)) + 1;  // layers
  static constexpr int NH = NL - 1;                 // hidden layers
  static constexpr int kWidth[NL + 1] = {D, H..., 1};
  static constexpr int HMAX = max_of({H...});
  static constexpr int OB = 4;  // outputs per register block (C x G x OB accumulators)
  static constexpr int woff(int k) {
    int o = 0;
    for (int j = 0; j < k; ++j) o += kWidth[j + 1] * (kWidth[j] + 1);
    return o;
  }
  static constexpr int boff(int k) { return woff(k) + kWidth[k + 1] * kWidth[k]; }
  static constexpr int P = woff(NL);
  // One group's storage, in vectors: per hidden layer k its activation jets A_k [n][C][G] and
  // its pre-activations' input derivatives Zi_k [n][D][G] (kept for the reverse pass).
  static constexpr int aoff(int k) {
    int o = 0;
    for (int j = 0; j < k; ++j) o += kWidth[j + 1] * C * G;
    return o;
  }
  static constexpr int zoff(int k) {
    int o = 0;
    for (int j = 0; j < k; ++j) o += kWidth[j + 1] * D * G;
    return o;
  }
  static constexpr int kA = aoff(NH), kZi = zoff(NH);
  // Vectors of the workspace: lane accumulators of every weight, A, Zi, the value block of one
  // layer [HMAX][G], the adjoints Ab and Zb [HMAX][C][G], the group's inputs and outputs.
  static constexpr int kVectors = P + kA + kZi + HMAX * G + 2 * HMAX * C * G + 4 * C * G + 2;
  static constexpr size_t kScalars = size_t(kVectors) * L + P + 64 / sizeof(T);

  static_assert(HMAX % OB == 0);
  static_assert(((H % OB == 0) && ...), "hidden widths must be multiples of the register block");

  struct Buffers {
    V *dw, *A, *Zi, *Zv, *Ab, *Zb, *X, *Y, *Gd, *K;
    T* Wt;  // the hidden layers' weights transposed, [in][out] per layer
  };

  static Buffers buffers(FusedWorkspace<T>& ws) {
    if (ws.buf.size() < kScalars) ws.buf.assign(kScalars, T(0));
    const uintptr_t raw = reinterpret_cast<uintptr_t>(ws.buf.data());
    V* v = reinterpret_cast<V*>((raw + 63) & ~uintptr_t(63));
    Buffers b;
    b.dw = v, v += P;
    b.A = v, v += kA;
    b.Zi = v, v += kZi;
    b.Zv = v, v += HMAX * G;
    b.Ab = v, v += HMAX * C * G;
    b.Zb = v, v += HMAX * C * G;
    b.X = v, v += C * G;  // D x G used
    b.Y = v, v += C * G;  // G used
    b.Gd = v, v += C * G;
    b.K = v, v += C * G;
    v += 2;
    b.Wt = reinterpret_cast<T*>(v);
    return b;
  }

  // Z = W A + b of hidden layer k >= 1 from the previous layer's jets: the values into Zv
  // [NO][G], the input derivatives into Zi [NO][D][G]. Wt: [NI][NO].
  template <int NI, int NO>
  static void forward_dense(const T* Wt, const T* bias, const V* Ain, V* Zv, V* Zi) {
    for (int o0 = 0; o0 < NO; o0 += OB) {
      V acc[OB][C][G];
      unroll<OB>([&](auto ob) {
        unroll<C>([&](auto c) {
          unroll<G>([&](auto g) { acc[ob][c][g] = V{} + (c == 0 ? bias[o0 + ob] : T(0)); });
        });
      });
      for (int i = 0; i < NI; ++i) {
        V a[C][G];
        unroll<C>([&](auto c) { unroll<G>([&](auto g) { a[c][g] = Ain[(i * C + c) * G + g]; }); });
        const T* wr = Wt + i * NO + o0;
        unroll<OB>([&](auto ob) {
          const T w = wr[ob];
          unroll<C>([&](auto c) { unroll<G>([&](auto g) { acc[ob][c][g] += w * a[c][g]; }); });
        });
      }
      unroll<OB>([&](auto ob) {
        unroll<G>([&](auto g) { Zv[(o0 + ob) * G + g] = acc[ob][0][g]; });
        unroll<D>([&](auto i) {
          unroll<G>([&](auto g) { Zi[((o0 + ob) * D + i) * G + g] = acc[ob][1 + i][g]; });
        });
      });
    }
  }

  // The sigmoid on a layer's jets: A = (s0, s1 z_i) from the values Zv and Zi.
  template <int N>
  static void sigmoid(V* Zv, const V* Zi, V* A) {
    Eigen::Map<Eigen::Array<T, N * G * L, 1>> z(reinterpret_cast<T*>(Zv));
    z = (T(1) + (-z).exp()).inverse();
    for (int o = 0; o < N; ++o)
      unroll<G>([&](auto g) {
        const V s0 = Zv[o * G + g], s1 = s0 - s0 * s0;
        A[(o * C) * G + g] = s0;
        unroll<D>([&](auto i) { A[(o * C + 1 + i) * G + g] = s1 * Zi[(o * D + i) * G + g]; });
      });
  }

  // Adjoint of the sigmoid's jet map: Zb from Ab, given s0 (in A) and Zi.
  template <int N>
  static void sigmoid_back(const V* A, const V* Zi, const V* Ab, V* Zb) {
    for (int o = 0; o < N; ++o)
      unroll<G>([&](auto g) {
        const V s0 = A[(o * C) * G + g], s1 = s0 - s0 * s0, s2 = s1 - T(2) * s0 * s1;
        V z0 = Ab[(o * C) * G + g] * s1;
        unroll<D>([&](auto i) {
          const V ab = Ab[(o * C + 1 + i) * G + g];
          z0 += ab * s2 * Zi[(o * D + i) * G + g];
          Zb[(o * C + 1 + i) * G + g] = ab * s1;
        });
        Zb[(o * C) * G + g] = z0;
      });
  }

  // Lane accumulators of layer k's weights and biases (k >= 1): dW[o][i] += sum_c,g Zb[o][c][g]
  // A_in[i][c][g], db[o] += sum_g Zb[o][0][g].
  template <int NI, int NO>
  static void weight_grad(const V* Zb, const V* Ain, V* dW, V* db) {
    static_assert(NO % 2 == 0);
    for (int o0 = 0; o0 < NO; o0 += 2) {
      V z[2][C][G];
      unroll<2>([&](auto ob) {
        unroll<C>([&](auto c) { unroll<G>([&](auto g) { z[ob][c][g] = Zb[((o0 + ob) * C + c) * G + g]; }); });
      });
      for (int i = 0; i < NI; ++i) {
        V a[C][G];
        unroll<C>([&](auto c) { unroll<G>([&](auto g) { a[c][g] = Ain[(i * C + c) * G + g]; }); });
        // One short chain per vector of points, then their sum: the loop is not bound by
        // the latency of a chain of C x G dependent FMAs.
        unroll<2>([&](auto ob) {
          V part[G];
          unroll<G>([&](auto g) {
            part[g] = z[ob][0][g] * a[0][g];
            unroll<C - 1>([&](auto c) { part[g] += z[ob][1 + c][g] * a[1 + c][g]; });
          });
          V sum = part[0];
          unroll<G - 1>([&](auto g) { sum += part[1 + g]; });
          dW[(o0 + ob) * NI + i] += sum;
        });
      }
      unroll<2>([&](auto ob) {
        V acc = db[o0 + ob];
        unroll<G>([&](auto g) { acc += z[ob][0][g]; });
        db[o0 + ob] = acc;
      });
    }
  }

  // Ab = W^T Zb of layer k >= 1 (W row-major [NO][NI]).
  // Inputs per register block here: the block's accumulators and one row of Zb must fit the 32
  // vector registers with room to spare (2D: 4 x 3 x 2 + 6 spilled).
  static constexpr int IB = OB * C * G + C * G <= 26 ? OB : OB / 2;

  template <int NI, int NO>
  static void backward_input(const T* W, const V* Zb, V* Ab) {
    for (int i0 = 0; i0 < NI; i0 += IB) {
      V acc[IB][C][G];
      unroll<IB>([&](auto ib) {
        unroll<C>([&](auto c) { unroll<G>([&](auto g) { acc[ib][c][g] = V{}; }); });
      });
      for (int o = 0; o < NO; ++o) {
        V z[C][G];
        unroll<C>([&](auto c) { unroll<G>([&](auto g) { z[c][g] = Zb[(o * C + c) * G + g]; }); });
        const T* wr = W + o * NI + i0;
        unroll<IB>([&](auto ib) {
          const T w = wr[ib];
          unroll<C>([&](auto c) { unroll<G>([&](auto g) { acc[ib][c][g] += w * z[c][g]; }); });
        });
      }
      unroll<IB>([&](auto ib) {
        unroll<C>([&](auto c) { unroll<G>([&](auto g) { Ab[((i0 + ib) * C + c) * G + g] = acc[ib][c][g]; }); });
      });
    }
  }

  static LossValues run(const T* params, const LossBatch<T>& batch, const LossWeights& w, T* grad,
                        FusedWorkspace<T>& ws) {
    const Buffers b = buffers(ws);
    const int m = batch.m;
    // The hidden layers' weights transposed for the forward products (k >= 1).
    unroll<NL - 1>([&](auto km1) {
      constexpr int k = km1 + 1;
      if constexpr (k < NL - 1) {
        constexpr int NI = kWidth[k], NO = kWidth[k + 1];
        const T* W = params + woff(k);
        T* Wt = b.Wt + woff(k);
        for (int o = 0; o < NO; ++o)
          for (int i = 0; i < NI; ++i) Wt[i * NO + o] = W[o * NI + i];
      }
    });
    if (grad)
      for (int p = 0; p < P; ++p) b.dw[p] = V{};
    V sz = V{}, sf = V{};
    const T inv_m = m > 0 ? T(1) / T(m) : T(0);
    const T cz = T(w.z) * inv_m * T(2), cf = T(w.f) * inv_m * T(2);
    const bool use_z = w.z != 0, use_f = w.f != 0;
    for (int p0 = 0; p0 < m; p0 += G * L) {
      load_group<T, D, G, L>(batch, p0, b.X, b.Gd, b.Y, b.K);
      // Layer 0: z = W x + b, z_i = W[:, i] (the input jet is (x, e_i)).
      {
        constexpr int NO = kWidth[1];
        const T* W0 = params + woff(0);
        const T* b0 = params + boff(0);
        for (int o = 0; o < NO; ++o)
          unroll<G>([&](auto g) {
            V z = V{} + b0[o];
            unroll<D>([&](auto j) { z += W0[o * D + j] * b.X[j * G + g]; });
            b.Zv[o * G + g] = z;
            unroll<D>([&](auto j) { b.Zi[(o * D + j) * G + g] = V{} + W0[o * D + j]; });
          });
        sigmoid<NO>(b.Zv, b.Zi, b.A);
      }
      unroll<NH - 1>([&](auto km1) {
        constexpr int k = km1 + 1;
        constexpr int NI = kWidth[k], NO = kWidth[k + 1];
        forward_dense<NI, NO>(b.Wt + woff(k), params + boff(k), b.A + aoff(k - 1), b.Zv, b.Zi + zoff(k));
        sigmoid<NO>(b.Zv, b.Zi + zoff(k), b.A + aoff(k));
      });
      // The linear output layer and the losses.
      constexpr int NI = kWidth[NH];
      const V* Al = b.A + aoff(NH - 1);
      const T* Wo = params + woff(NH);
      V y[C][G];
      unroll<C>([&](auto c) { unroll<G>([&](auto g) { y[c][g] = V{} + (c == 0 ? params[boff(NH)] : T(0)); }); });
      for (int i = 0; i < NI; ++i) {
        const T wi = Wo[i];
        unroll<C>([&](auto c) { unroll<G>([&](auto g) { y[c][g] += wi * Al[(i * C + c) * G + g]; }); });
      }
      V yb[C][G];
      unroll<G>([&](auto g) {
        const V k = b.K[g];
        const V r = y[0][g] - b.Y[g];
        if (use_z) sz += k * r * r;
        yb[0][g] = use_z ? cz * k * r : V{};
        unroll<D>([&](auto i) {
          const V ri = y[1 + i][g] - b.Gd[i * G + g];
          if (use_f) sf += k * ri * ri;
          yb[1 + i][g] = use_f ? cf * k * ri : V{};
        });
      });
      if (!grad) continue;
      // Reverse: the output layer.
      {
        V* dW = b.dw + woff(NH);
        for (int i = 0; i < NI; ++i) {
          V acc = dW[i];
          unroll<C>([&](auto c) {
            unroll<G>([&](auto g) {
              acc += yb[c][g] * Al[(i * C + c) * G + g];
              b.Ab[(i * C + c) * G + g] = Wo[i] * yb[c][g];
            });
          });
          dW[i] = acc;
        }
        V acc = b.dw[boff(NH)];
        unroll<G>([&](auto g) { acc += yb[0][g]; });
        b.dw[boff(NH)] = acc;
      }
      // The hidden layers, last to first.
      unroll<NH>([&](auto r) {
        constexpr int k = NH - 1 - r;  // hidden layer k: the output of weight layer k
        constexpr int NO = kWidth[k + 1];
        sigmoid_back<NO>(b.A + aoff(k), b.Zi + zoff(k), b.Ab, b.Zb);
        if constexpr (k >= 1) {
          constexpr int NIk = kWidth[k];
          weight_grad<NIk, NO>(b.Zb, b.A + aoff(k - 1), b.dw + woff(k), b.dw + boff(k));
          backward_input<NIk, NO>(params + woff(k), b.Zb, b.Ab);
        } else {
          V* dW = b.dw + woff(0);
          V* db = b.dw + boff(0);
          for (int o = 0; o < NO; ++o) {
            V acc = db[o];
            unroll<G>([&](auto g) { acc += b.Zb[(o * C) * G + g]; });
            db[o] = acc;
            unroll<D>([&](auto j) {
              V a = dW[o * D + j];
              unroll<G>([&](auto g) {
                a += b.Zb[(o * C) * G + g] * b.X[j * G + g];
                a += b.Zb[(o * C + 1 + j) * G + g];
              });
              dW[o * D + j] = a;
            });
          }
        }
      });
    }
    return lane_totals<T, L>(sz, sf, inv_m, w, b.dw, P, grad);
  }
};

// Net-2 with two inputs by double backpropagation: the value by a forward pass, the input
// gradient by a backward pass, then dL/dparams by the reverse of both. Per point this costs six
// products of the [H2, H1] layer's size (forward, its transpose for the input gradient, and in
// the reverse: one of each orientation and the two-channel weight gradient) against nine for
// order-1 jets (three channels through forward, input adjoint and weight gradient): the jets'
// cost grows with the input dimension, double backpropagation's does not. Groups of G vectors of
// points, weights broadcast, lane accumulators per weight, as Fused.
template <class T, int H1, int H2>
struct DoubleBackprop2 {
  using V = typename Simd<T>::V;
  static constexpr int L = Simd<T>::L;
  static constexpr int D = 2;
  static constexpr int G = 4;   // vectors of points per group
  static constexpr int OB = 4;  // outputs per register block (OB x G accumulators)
  static constexpr int W0 = 0, B0 = H1 * D, W1 = H1 * (D + 1), B1 = W1 + H2 * H1, W2 = B1 + H2, B2 = W2 + H2;
  static constexpr int P = B2 + 1;
  // One group's vectors, [neuron][G] each: A0, A1 (the activations s0), Zb1 = w2 s1(z1),
  // Ab0 = W1^T Zb1, Zb0 = Ab0 s1(z0), and the reverse's Zbh0, Abh0, Zh0, Zbh1, Zh1, Ah0.
  enum { kA0, kA1, kZb1, kAb0, kZb0, kZbh0, kAbh0, kZh0, kZbh1, kZh1, kAh0, kBlocks };
  static constexpr int HM = H1 > H2 ? H1 : H2;
  static constexpr int kVectors = P + kBlocks * HM * G + 4 * D * G + 2;
  static constexpr size_t kScalars = size_t(kVectors) * L + 64 / sizeof(T);
  static_assert(H1 % OB == 0 && H2 % OB == 0);

  // out[o][g] = bias[o] (or 0) + sum_i M[o * so + i * si] in[i][g], o < NO, i < NI: a product with
  // the weights at any strides (so: W1 as stored or transposed).
  template <int NI, int NO>
  static void dense(const T* M, int so, int si, const T* bias, const V* in, V* out) {
    for (int o0 = 0; o0 < NO; o0 += OB) {
      V acc[OB][G];
      unroll<OB>([&](auto ob) { unroll<G>([&](auto g) { acc[ob][g] = V{} + (bias ? bias[o0 + ob] : T(0)); }); });
      for (int i = 0; i < NI; ++i) {
        // The block's weights broadcast first, then each input vector loaded once and used by
        // the OB products in a row (GCC otherwise folds a load into every product: 5 % slower).
        V w[OB];
        unroll<OB>([&](auto ob) { w[ob] = V{} + M[(o0 + ob) * so + i * si]; });
        unroll<G>([&](auto g) {
          const V a = in[i * G + g];
          unroll<OB>([&](auto ob) { acc[ob][g] += w[ob] * a; });
        });
      }
      unroll<OB>([&](auto ob) { unroll<G>([&](auto g) { out[(o0 + ob) * G + g] = acc[ob][g]; }); });
    }
  }

  template <int N>
  static void sigmoid(V* z) {
    Eigen::Map<Eigen::Array<T, N * G * L, 1>> m(reinterpret_cast<T*>(z));
    m = (T(1) + (-m).exp()).inverse();
  }

  static LossValues run(const T* params, const LossBatch<T>& batch, const LossWeights& w, T* grad,
                        FusedWorkspace<T>& ws) {
    if (ws.buf.size() < kScalars) ws.buf.assign(kScalars, T(0));
    V* v = reinterpret_cast<V*>((reinterpret_cast<uintptr_t>(ws.buf.data()) + 63) & ~uintptr_t(63));
    V* dw = v;
    V* blk[kBlocks];
    for (int k = 0; k < kBlocks; ++k) blk[k] = v + P + k * HM * G;
    V* X = v + P + kBlocks * HM * G;  // [D][G]
    V* Gd = X + D * G;                // [D][G]
    V* Y = Gd + D * G;                // [G]
    V* K = Y + G;                     // [G]
    V *A0 = blk[kA0], *A1 = blk[kA1], *Zb1 = blk[kZb1], *Ab0 = blk[kAb0], *Zb0 = blk[kZb0];
    const T* w0 = params + W0;
    const T* w1 = params + W1;
    const T* w2 = params + W2;
    const int m = batch.m;
    if (grad)
      for (int p = 0; p < P; ++p) dw[p] = V{};
    V sz = V{}, sf = V{};
    const T inv_m = m > 0 ? T(1) / T(m) : T(0);
    const T cz = T(w.z) * inv_m * T(2), cf = T(w.f) * inv_m * T(2);
    const bool use_z = w.z != 0, use_f = w.f != 0;
    for (int p0 = 0; p0 < m; p0 += G * L) {
      load_group<T, D, G, L>(batch, p0, X, Gd, Y, K);
      // Forward: A0 = s(W0 x + b0), A1 = s(W1 A0 + b1), f = w2 . A1 + b2.
      for (int o = 0; o < H1; ++o)
        unroll<G>([&](auto g) { A0[o * G + g] = V{} + params[B0 + o] + w0[o * D] * X[g] + w0[o * D + 1] * X[G + g]; });
      sigmoid<H1>(A0);
      dense<H1, H2>(w1, H1, 1, params + B1, A0, A1);
      sigmoid<H2>(A1);
      // Backward for the input gradient: Zb1 = w2 s1(z1), Ab0 = W1^T Zb1, Zb0 = Ab0 s1(z0),
      // grad_x f = W0^T Zb0.
      V f[G], gx[D][G];
      unroll<G>([&](auto g) { f[g] = V{} + params[B2]; });
      for (int o = 0; o < H2; ++o)
        unroll<G>([&](auto g) {
          const V a = A1[o * G + g];
          f[g] += w2[o] * a;
          Zb1[o * G + g] = w2[o] * (a - a * a);
        });
      dense<H2, H1>(w1, 1, H1, nullptr, Zb1, Ab0);
      unroll<D>([&](auto j) { unroll<G>([&](auto g) { gx[j][g] = V{}; }); });
      for (int o = 0; o < H1; ++o)
        unroll<G>([&](auto g) {
          const V a = A0[o * G + g], zb = Ab0[o * G + g] * (a - a * a);
          Zb0[o * G + g] = zb;
          unroll<D>([&](auto j) { gx[j][g] += w0[o * D + j] * zb; });
        });
      // The losses and their adjoints: fb = dL/df, gb = dL/dgrad_x f.
      V fb[G], gb[D][G];
      unroll<G>([&](auto g) {
        const V k = K[g];
        const V r = f[g] - Y[g];
        if (use_z) sz += k * r * r;
        fb[g] = use_z ? cz * k * r : V{};
        unroll<D>([&](auto j) {
          const V rj = gx[j][g] - Gd[j * G + g];
          if (use_f) sf += k * rj * rj;
          gb[j][g] = use_f ? cf * k * rj : V{};
        });
      });
      if (!grad) continue;
      V *Zbh0 = blk[kZbh0], *Abh0 = blk[kAbh0], *Zh0 = blk[kZh0], *Zbh1 = blk[kZbh1], *Zh1 = blk[kZh1],
        *Ah0 = blk[kAh0];
      // Reverse of grad_x f = W0^T Zb0 and of Zb0 = Ab0 s1(z0).
      for (int o = 0; o < H1; ++o)
        unroll<G>([&](auto g) {
          V zbh = V{};
          unroll<D>([&](auto j) {
            zbh += w0[o * D + j] * gb[j][g];
            dw[W0 + o * D + j] += Zb0[o * G + g] * gb[j][g];
          });
          const V a = A0[o * G + g], s1 = a - a * a, s2 = s1 - T(2) * a * s1;
          Zbh0[o * G + g] = zbh;
          Abh0[o * G + g] = zbh * s1;
          Zh0[o * G + g] = zbh * Ab0[o * G + g] * s2;
        });
      // Reverse of Ab0 = W1^T Zb1: Zbh1 = W1 Abh0 (and dW1 += Zb1 Abh0^T below).
      dense<H1, H2>(w1, H1, 1, nullptr, Abh0, Zbh1);
      // Reverse of Zb1 = w2 s1(z1), of f = w2 . A1 + b2 and of A1 = s(z1).
      {
        V db2 = dw[B2];
        for (int o = 0; o < H2; ++o) {
          V dw2 = dw[W2 + o];
          unroll<G>([&](auto g) {
            const V a = A1[o * G + g], s1 = a - a * a, s2 = s1 - T(2) * a * s1, zbh = Zbh1[o * G + g];
            dw2 += zbh * s1 + fb[g] * a;
            Zh1[o * G + g] = zbh * w2[o] * s2 + fb[g] * w2[o] * s1;
          });
          dw[W2 + o] = dw2;
        }
        unroll<G>([&](auto g) { db2 += fb[g]; });
        dw[B2] = db2;
      }
      // dW1 += Zh1 A0^T + Zb1 Abh0^T, db1 += Zh1.
      for (int o0 = 0; o0 < H2; o0 += 2) {
        V z[2][2][G];
        unroll<2>([&](auto ob) {
          unroll<G>([&](auto g) {
            z[ob][0][g] = Zh1[(o0 + ob) * G + g];
            z[ob][1][g] = Zb1[(o0 + ob) * G + g];
          });
        });
        for (int i = 0; i < H1; ++i) {
          V a[2][G];
          unroll<G>([&](auto g) {
            a[0][g] = A0[i * G + g];
            a[1][g] = Abh0[i * G + g];
          });
          unroll<2>([&](auto ob) {
            V part[2];
            unroll<2>([&](auto c) {
              part[c] = z[ob][c][0] * a[c][0];
              unroll<G - 1>([&](auto g) { part[c] += z[ob][c][1 + g] * a[c][1 + g]; });
            });
            dw[W1 + (o0 + ob) * H1 + i] += part[0] + part[1];
          });
        }
        unroll<2>([&](auto ob) {
          V acc = dw[B1 + o0 + ob];
          unroll<G>([&](auto g) { acc += z[ob][0][g]; });
          dw[B1 + o0 + ob] = acc;
        });
      }
      // Reverse of z1 = W1 A0 + b1: Ah0 = W1^T Zh1; of A0 = s(z0) and z0 = W0 x + b0.
      dense<H2, H1>(w1, 1, H1, nullptr, Zh1, Ah0);
      for (int o = 0; o < H1; ++o) {
        V db = dw[B0 + o], dx[D];
        unroll<D>([&](auto j) { dx[j] = dw[W0 + o * D + j]; });
        unroll<G>([&](auto g) {
          const V a = A0[o * G + g], zh = Zh0[o * G + g] + Ah0[o * G + g] * (a - a * a);
          db += zh;
          unroll<D>([&](auto j) { dx[j] += zh * X[j * G + g]; });
        });
        dw[B0 + o] = db;
        unroll<D>([&](auto j) { dw[W0 + o * D + j] = dx[j]; });
      }
    }
    return lane_totals<T, L>(sz, sf, inv_m, w, dw, P, grad);
  }
};

bool hidden_is(const NetworkDesc& desc, std::initializer_list<int> h) {
  return desc.hidden.size() == h.size() && std::equal(h.begin(), h.end(), desc.hidden.begin());
}

}  // namespace

bool fused_order1_supported(const NetworkDesc& desc) {
  return (desc.input_dim == 1 || desc.input_dim == 2) && desc.activation == "sigmoid" &&
         (hidden_is(desc, {16, 32, 16}) || hidden_is(desc, {32, 32}));
}

template <class T>
LossValues fused_data_loss_grad(const NetworkDesc& desc, const T* params, const LossBatch<T>& batch,
                                const LossWeights& w, T* grad, FusedWorkspace<T>& ws) {
  const bool d1 = desc.input_dim == 1;
  if (hidden_is(desc, {16, 32, 16}) && desc.input_dim <= 2)
    return d1 ? Fused<T, 1, 16, 32, 16>::run(params, batch, w, grad, ws)
              : Fused<T, 2, 16, 32, 16>::run(params, batch, w, grad, ws);
  if (hidden_is(desc, {32, 32}) && desc.input_dim <= 2)
    return d1 ? Fused<T, 1, 32, 32>::run(params, batch, w, grad, ws)
              : DoubleBackprop2<T, 32, 32>::run(params, batch, w, grad, ws);
  throw std::invalid_argument("fused_data_loss_grad: network shape not compiled in (fused_order1_supported)");
}

template LossValues fused_data_loss_grad<float>(const NetworkDesc&, const float*, const LossBatch<float>&,
                                                const LossWeights&, float*, FusedWorkspace<float>&);
template LossValues fused_data_loss_grad<double>(const NetworkDesc&, const double*, const LossBatch<double>&,
                                                 const LossWeights&, double*, FusedWorkspace<double>&);

}  // namespace yarnhom::cpu
