#pragma once
// The passes of the epoch kernel (cpu/epoch_kernel.hpp); included by cpu/epoch_kernel.cpp only.
//
// One pass takes points of one kind through the network: the data points with jets of order
// ORDER (3 when L_C is on), or the off-domain points with jets of order 1. A jet is C channels
// per neuron (core/jet_layout.hpp): the value, then the input derivatives of order 1, 2, 3.
//
// Layout, in vectors V of L points (16 floats or 8 doubles), a group being G vectors:
//   A_k[o][c][g]    activation jet of hidden layer k (channel 0 is s0 = sigmoid(z)), kept for
//                   the reverse pass; Z_k[o][c-1][g] the pre-activation jet's channels c >= 1
//                   (the sigmoid's reverse needs them; channel 0 enters only through s0).
//   dw[p]           a lane accumulator per weight: dL/dparam_p = sum over lanes, at the end.
// Forward, per group:
//   layer 0:   z = W x + b, z_i = W[:, i], higher channels 0 (the input jet is (x, e_i, 0, 0));
//   layer k:   Z = W A + b (b in channel 0 only): the same W maps every channel;
//   sigmoid:   a = s0, a_i = s1 z_i, a_ij = s2 z_i z_j + s1 z_ij,
//              a_ijk = s3 z_i z_j z_k + s2 (z_ij z_k + z_ik z_j + z_jk z_i) + s1 z_ijk,
//              with s1 = s0 (1 - s0), s2 = s1 (1 - 2 s0), s3 = s1 (1 - 6 s0 + 6 s0^2);
//   output:    y = w_out . A_last + b_out, every channel (a linear layer).
// Losses on the output jet y (per point, before the means):
//   data:      k (y - y_data)^2, k |y_i - g_data,i|^2 (k: the point's weight), |y_ijk| summed over
//              the distinct third derivatives (L_C, exact);
//   off-domain: relu(-y_i n_i)^2 (L_S).
// Reverse, per group: yb = dL/dy from the losses; the output layer sends yb to its weights
// (dw_i += yb . A_last[i]) and to A_last (Ab = w_i yb); each hidden layer, last to first,
// undoes the sigmoid's jet map (every product of the forward formulas sends its adjoint to each
// factor; every s_n(z0) sends its adjoint times s_{n+1} to z0, hence s4 = s1 (1 - 2 s0)
// (1 - 12 s0 + 12 s0^2)), then dW += Zb A_in^T over channels and points, db += Zb's channel 0,
// and Ab = W^T Zb for the layer below; layer 0's weights get Zb_0 x^T plus Zb's channel e_i in
// column i (its z_i is W[:, i]); its higher channels are constants and need no adjoint.
#include <Eigen/Core>

#include <cstdint>
#include <utility>

#include "core/jet_layout.hpp"
#include "cpu/simd_block.hpp"

namespace yarnhom::cpu::epoch {

using simd::Simd;
using simd::unroll;

// The sum of a vector's lanes, by halves (16 -> 8 -> 4 floats, 8 -> 4 -> 2 doubles) and then
// in lane order: a fixed order, in vector adds.
template <class T>
inline T lane_sum(const typename Simd<T>::V& v) {
  typedef T H __attribute__((vector_size(32)));
  typedef T Q __attribute__((vector_size(16)));
  H a, b;
  __builtin_memcpy(&a, &v, 32);
  __builtin_memcpy(&b, reinterpret_cast<const char*>(&v) + 32, 32);
  const H h = a + b;
  Q c, d;
  __builtin_memcpy(&c, &h, 16);
  __builtin_memcpy(&d, reinterpret_cast<const char*>(&h) + 16, 16);
  const Q q = c + d;
  T s = q[0];
  for (int l = 1; l < int(16 / sizeof(T)); ++l) s += q[l];
  return s;
}

// The network: input dimension D, hidden widths H..., a linear output.
template <int D, int... H>
struct Shape {
  static constexpr int NL = int(sizeof...(H)) + 1;  // weight layers
  static constexpr int NH = NL - 1;                 // hidden layers
  static constexpr int kWidth[NL + 1] = {D, H..., 1};
  static constexpr int HMAX = [] {
    int m = 0;
    for (int w : {H...}) m = w > m ? w : m;
    return m;
  }();
  static constexpr int woff(int k) {
    int o = 0;
    for (int j = 0; j < k; ++j) o += kWidth[j + 1] * (kWidth[j] + 1);
    return o;
  }
  static constexpr int boff(int k) { return woff(k) + kWidth[k + 1] * kWidth[k]; }
  static constexpr int P = woff(NL);
};

// The loss sums of one pass (vectors: summed across lanes by the caller).
template <class V>
struct PassSums {
  V z{}, f{}, c{}, s{};
};

// The per-point inputs of a pass's loss head, in the caller's arrays; coefficients are the
// loss weights over the point counts (the adjoint of the mean).
template <class T>
struct PassInputs {
  int n = 0;
  const T* x = nullptr;   // [n, D]
  const T* y = nullptr;   // data: [n]
  const T* g = nullptr;   // data: [n, D]
  const T* wt = nullptr;  // data: [n] or null
  const T* no = nullptr;  // off-domain: [n, D] outward normals
  bool use_z = false, use_f = false, use_c = false;
  T cz = 0, cf = 0, cc = 0, cs = 0;  // 2 w_Z / M, 2 w_F / M, w_C / M, 2 w_S / K
};

// One kind of points through the network: jets of order ORDER; OFF selects the off-domain
// head (L_S) instead of the data head (L_Z, L_F, L_C).
template <class T, bool OFF, int ORDER, int D, int... H>
struct Pass {
  using S = Shape<D, H...>;
  using V = typename Simd<T>::V;
  static constexpr int L = Simd<T>::L;
  static constexpr int NL = S::NL, NH = S::NH, HMAX = S::HMAX, P = S::P;
  static constexpr int C = jet_channels(D, ORDER);
  static constexpr int CZ = C - 1;  // stored pre-activation channels 1..C-1
  static constexpr int G = C <= 3 ? 2 : 1;           // vectors of points per group
  static constexpr int OB = C * G * 4 <= 24 ? 4 : 2;  // outputs per register block (OB x C x G
                                                      // accumulators: at most 24 of 32 registers)
  static constexpr int NCHAIN = C * G < 4 ? C * G : 4;  // independent partial sums per dot product
  static_assert(((H % OB == 0) && ...), "hidden widths must be multiples of the register block");

  static constexpr int aoff(int k) {
    int o = 0;
    for (int j = 0; j < k; ++j) o += S::kWidth[j + 1] * C * G;
    return o;
  }
  static constexpr int zoff(int k) {
    int o = 0;
    for (int j = 0; j < k; ++j) o += S::kWidth[j + 1] * CZ * G;
    return o;
  }
  // Scratch vectors of one group: A, Z, the value block Zv, the adjoints Ab and Zb, the inputs
  // X [D][G], and the head's per-point data: Y, K (weight), M (1 in range, 0 past the end),
  // Gd or N [D][G].
  static constexpr int kScratch = aoff(NH) + zoff(NH) + HMAX * G + 2 * HMAX * C * G + 2 * D * G + 3 * G;

  struct Buf {
    V *A, *Z, *Zv, *Ab, *Zb, *X, *Y, *K, *M, *Gd;
  };
  static Buf buffers(V* v) {
    Buf b;
    b.A = v, v += aoff(NH);
    b.Z = v, v += zoff(NH);
    b.Zv = v, v += HMAX * G;
    b.Ab = v, v += HMAX * C * G;
    b.Zb = v, v += HMAX * C * G;
    b.X = v, v += D * G;
    b.Gd = v, v += D * G;
    b.Y = v, v += G;
    b.K = v, v += G;
    b.M = v;
    return b;
  }

  // ---- the sigmoid's jet map, per neuron (FIRST: layer 0, whose z has no channels past 1+D)
  template <bool FIRST>
  static inline void sig_forward(const V s0, const V* z, V* a) {
    const V s1 = s0 - s0 * s0;
    const V s2 = s1 - T(2) * s0 * s1;
    const V s3 = s1 * (T(1) - T(6) * s0 + T(6) * s0 * s0);
    a[0] = s0;
    if constexpr (ORDER >= 1) unroll<D>([&](auto i) { a[1 + i] = s1 * z[1 + i]; });
    if constexpr (ORDER >= 2)
      unroll<jet_num_pairs(D)>([&](auto q) {
        constexpr JetPair e = jet_pair(D, q);
        constexpr int c = jet_first(D, 2) + q;
        a[c] = s2 * z[1 + e.i] * z[1 + e.j];
        if constexpr (!FIRST) a[c] += s1 * z[c];
      });
    if constexpr (ORDER >= 3)
      unroll<jet_num_triples(D)>([&](auto t) {
        constexpr JetTriple e = jet_triple(D, t);
        constexpr int c = jet_first(D, 3) + t;
        constexpr int cij = jet_ch2(D, e.i, e.j), cik = jet_ch2(D, e.i, e.k), cjk = jet_ch2(D, e.j, e.k);
        const V zi = z[1 + e.i], zj = z[1 + e.j], zk = z[1 + e.k];
        a[c] = s3 * zi * zj * zk;
        if constexpr (!FIRST) a[c] += s2 * (z[cij] * zk + z[cik] * zj + z[cjk] * zi) + s1 * z[c];
      });
  }

  // Reverse of sig_forward: zb from ab. FIRST fills only zb[0..D] (the rest is not needed).
  template <bool FIRST>
  static inline void sig_backward(const V s0, const V* z, const V* ab, V* zb) {
    const V s1 = s0 - s0 * s0;
    const V u = T(1) - T(2) * s0;
    const V s2 = s1 * u;
    const V q6 = s0 - s0 * s0;  // s0 (1 - s0)
    const V s3 = s1 * (T(1) - T(6) * q6);
    const V s4 = s2 * (T(1) - T(12) * q6);
    constexpr int CB = FIRST ? 1 + D : C;
    unroll<CB>([&](auto c) { zb[c] = ab[c] * s1; });
    if constexpr (ORDER >= 1) unroll<D>([&](auto i) { zb[0] += ab[1 + i] * s2 * z[1 + i]; });
    if constexpr (ORDER >= 2)
      unroll<jet_num_pairs(D)>([&](auto q) {
        constexpr JetPair e = jet_pair(D, q);
        constexpr int c = jet_first(D, 2) + q;
        const V g = ab[c];
        V t0 = s3 * z[1 + e.i] * z[1 + e.j];
        if constexpr (!FIRST) t0 += s2 * z[c];
        zb[0] += g * t0;
        const V gs2 = g * s2;
        zb[1 + e.i] += gs2 * z[1 + e.j];
        zb[1 + e.j] += gs2 * z[1 + e.i];
      });
    if constexpr (ORDER >= 3)
      unroll<jet_num_triples(D)>([&](auto t) {
        constexpr JetTriple e = jet_triple(D, t);
        constexpr int c = jet_first(D, 3) + t;
        constexpr int cij = jet_ch2(D, e.i, e.j), cik = jet_ch2(D, e.i, e.k), cjk = jet_ch2(D, e.j, e.k);
        const V g = ab[c];
        const V zi = z[1 + e.i], zj = z[1 + e.j], zk = z[1 + e.k];
        V t0 = s4 * zi * zj * zk;
        V ti = s3 * zj * zk, tj = s3 * zi * zk, tk = s3 * zi * zj;
        if constexpr (!FIRST) {
          const V zij = z[cij], zik = z[cik], zjk = z[cjk];
          t0 += s3 * (zij * zk + zik * zj + zjk * zi) + s2 * z[c];
          ti += s2 * zjk, tj += s2 * zik, tk += s2 * zij;
          const V gs2 = g * s2;
          zb[cij] += gs2 * zk;
          zb[cik] += gs2 * zj;
          zb[cjk] += gs2 * zi;
        }
        zb[0] += g * t0;
        zb[1 + e.i] += g * ti;
        zb[1 + e.j] += g * tj;
        zb[1 + e.k] += g * tk;
      });
  }

  // The sigmoid on a layer of N neurons: s0 from the values Zv (Eigen's vectorized exp over the
  // block), then the jet map from Z (channels >= 1) into A.
  template <int N, bool FIRST>
  static void sigmoid(V* Zv, const V* Z, V* A) {
    Eigen::Map<Eigen::Array<T, N * G * L, 1>> s(reinterpret_cast<T*>(Zv));
    s = (T(1) + (-s).exp()).inverse();
    for (int o = 0; o < N; ++o)
      unroll<G>([&](auto g) {
        V z[C], a[C];
        unroll<CZ>([&](auto c) { z[1 + c] = Z[(o * CZ + c) * G + g]; });
        sig_forward<FIRST>(Zv[o * G + g], z, a);
        unroll<C>([&](auto c) { A[(o * C + c) * G + g] = a[c]; });
      });
  }

  template <int N, bool FIRST>
  static void sigmoid_back(const V* A, const V* Z, const V* Ab, V* Zb) {
    for (int o = 0; o < N; ++o)
      unroll<G>([&](auto g) {
        V z[C], ab[C], zb[C];
        unroll<CZ>([&](auto c) { z[1 + c] = Z[(o * CZ + c) * G + g]; });
        unroll<C>([&](auto c) { ab[c] = Ab[(o * C + c) * G + g]; });
        sig_backward<FIRST>(A[(o * C) * G + g], z, ab, zb);
        constexpr int CB = FIRST ? 1 + D : C;
        unroll<CB>([&](auto c) { Zb[(o * C + c) * G + g] = zb[c]; });
      });
  }

  // Z = W A + b of hidden layer k >= 1: values into Zv [NO][G], channels >= 1 into Z [NO][CZ][G].
  // W: row-major [NO][NI]; each weight is broadcast from memory into its FMAs (no transposed
  // copy: a broadcast costs one load wherever the weight sits).
  template <int NI, int NO>
  static void forward_dense(const T* W, const T* bias, const V* Ain, V* Zv, V* Z) {
    for (int o0 = 0; o0 < NO; o0 += OB) {
      V acc[OB][C][G];
      unroll<OB>([&](auto ob) {
        unroll<C>([&](auto c) {
          unroll<G>([&](auto g) { acc[ob][c][g] = V{} + (c == 0 ? bias[o0 + ob] : T(0)); });
        });
      });
      for (int i = 0; i < NI; ++i) {
        unroll<C>([&](auto c) {
          unroll<G>([&](auto g) {
            const V a = Ain[(i * C + c) * G + g];
            unroll<OB>([&](auto ob) { acc[ob][c][g] += W[(o0 + ob) * NI + i] * a; });
          });
        });
      }
      unroll<OB>([&](auto ob) {
        unroll<G>([&](auto g) { Zv[(o0 + ob) * G + g] = acc[ob][0][g]; });
        unroll<CZ>([&](auto c) {
          unroll<G>([&](auto g) { Z[((o0 + ob) * CZ + c) * G + g] = acc[ob][1 + c][g]; });
        });
      });
    }
  }

  // Lane accumulators of layer k >= 1: dW[o][i] += sum_{c,g} Zb[o][c][g] A_in[i][c][g],
  // db[o] += sum_g Zb[o][0][g]. Each dot product runs in NCHAIN independent partial sums, so
  // the loop is not bound by the latency of one chain of C x G dependent FMAs.
  template <int NI, int NO>
  static void weight_grad(const V* Zb, const V* Ain, V* dW, V* db) {
    static_assert(NO % 2 == 0);
    for (int o0 = 0; o0 < NO; o0 += 2) {
      V z[2][C * G];
      unroll<2>([&](auto ob) { unroll<C * G>([&](auto cg) { z[ob][cg] = Zb[(o0 + ob) * C * G + cg]; }); });
      for (int i = 0; i < NI; ++i) {
        const V* a = Ain + i * C * G;
        unroll<2>([&](auto ob) {
          V part[NCHAIN];
          unroll<NCHAIN>([&](auto q) { part[q] = z[ob][q] * a[q]; });
          unroll<C * G - NCHAIN>([&](auto r) {
            constexpr int cg = NCHAIN + r;
            part[cg % NCHAIN] += z[ob][cg] * a[cg];
          });
          V sum = part[0];
          unroll<NCHAIN - 1>([&](auto q) { sum += part[1 + q]; });
          dW[(o0 + ob) * NI + i] += sum;
        });
      }
      unroll<2>([&](auto ob) {
        V acc = db[o0 + ob];
        unroll<G>([&](auto g) { acc += z[ob][g]; });  // channel 0 is cg = 0..G-1
        db[o0 + ob] = acc;
      });
    }
  }

  // Ab = W^T Zb of layer k >= 1 (W row-major [NO][NI]).
  template <int NI, int NO>
  static void backward_input(const T* W, const V* Zb, V* Ab) {
    for (int i0 = 0; i0 < NI; i0 += OB) {
      V acc[OB][C * G];
      unroll<OB>([&](auto ib) { unroll<C * G>([&](auto cg) { acc[ib][cg] = V{}; }); });
      for (int o = 0; o < NO; ++o) {
        const T* wr = W + o * NI + i0;
        unroll<C * G>([&](auto cg) {
          const V z = Zb[o * C * G + cg];
          unroll<OB>([&](auto ib) { acc[ib][cg] += wr[ib] * z; });
        });
      }
      unroll<OB>([&](auto ib) { unroll<C * G>([&](auto cg) { Ab[(i0 + ib) * C * G + cg] = acc[ib][cg]; }); });
    }
  }

  // The whole pass over in.n points. dw: the lane accumulators (null: no gradient); scratch:
  // kScratch vectors.
  static void run(const T* params, const PassInputs<T>& in, V* dw, V* scratch,
                  PassSums<V>& sums) {
    const Buf b = buffers(scratch);
    for (int p0 = 0; p0 < in.n; p0 += G * L) {
      // The group's points; lanes past the end have zero inputs, weight and mask.
      for (int g = 0; g < G; ++g)
        for (int l = 0; l < L; ++l) {
          const int p = p0 + g * L + l;
          const bool ok = p < in.n;
          b.M[g][l] = ok ? T(1) : T(0);
          b.K[g][l] = ok ? (in.wt ? in.wt[p] : T(1)) : T(0);
          if constexpr (!OFF) b.Y[g][l] = ok ? in.y[p] : T(0);
          for (int j = 0; j < D; ++j) {
            b.X[j * G + g][l] = ok ? in.x[size_t(p) * D + j] : T(0);
            b.Gd[j * G + g][l] = ok ? (OFF ? in.no : in.g)[size_t(p) * D + j] : T(0);
          }
        }
      // Layer 0.
      {
        constexpr int NO = S::kWidth[1];
        const T* W0 = params + S::woff(0);
        const T* b0 = params + S::boff(0);
        for (int o = 0; o < NO; ++o)
          unroll<G>([&](auto g) {
            V z = V{} + b0[o];
            unroll<D>([&](auto j) { z += W0[o * D + j] * b.X[j * G + g]; });
            b.Zv[o * G + g] = z;
            if constexpr (ORDER >= 1)
              unroll<D>([&](auto j) { b.Z[(o * CZ + j) * G + g] = V{} + W0[o * D + j]; });
          });
        sigmoid<NO, true>(b.Zv, b.Z, b.A);
      }
      unroll<NH - 1>([&](auto km1) {
        constexpr int k = km1 + 1;
        constexpr int NI = S::kWidth[k], NO = S::kWidth[k + 1];
        forward_dense<NI, NO>(params + S::woff(k), params + S::boff(k), b.A + aoff(k - 1), b.Zv, b.Z + zoff(k));
        sigmoid<NO, false>(b.Zv, b.Z + zoff(k), b.A + aoff(k));
      });
      // The linear output layer.
      constexpr int NI = S::kWidth[NH];
      const V* Al = b.A + aoff(NH - 1);
      const T* Wo = params + S::woff(NH);
      V y[C][G];
      unroll<C>([&](auto c) { unroll<G>([&](auto g) { y[c][g] = V{} + (c == 0 ? params[S::boff(NH)] : T(0)); }); });
      for (int i = 0; i < NI; ++i) {
        const T wi = Wo[i];
        unroll<C>([&](auto c) { unroll<G>([&](auto g) { y[c][g] += wi * Al[(i * C + c) * G + g]; }); });
      }
      // The losses and their adjoints yb = dL/dy.
      V yb[C][G];
      unroll<C>([&](auto c) { unroll<G>([&](auto g) { yb[c][g] = V{}; }); });
      unroll<G>([&](auto g) {
        if constexpr (OFF) {
          V dot = V{};
          unroll<D>([&](auto i) { dot += y[1 + i][g] * b.Gd[i * G + g]; });
          const V r = dot < V{} ? dot : V{};  // -relu(-dot)
          sums.s += r * r;
          unroll<D>([&](auto i) { yb[1 + i][g] = in.cs * r * b.Gd[i * G + g]; });
        } else {
          const V k = b.K[g];
          if (in.use_z) {
            const V r = y[0][g] - b.Y[g];
            sums.z += k * r * r;
            yb[0][g] = in.cz * k * r;
          }
          if (in.use_f)
            unroll<D>([&](auto i) {
              const V r = y[1 + i][g] - b.Gd[i * G + g];
              sums.f += k * r * r;
              yb[1 + i][g] = in.cf * k * r;
            });
          if constexpr (ORDER >= 3)
            if (in.use_c)
              unroll<jet_num_triples(D)>([&](auto t) {
                constexpr int c = jet_first(D, 3) + t;
                const V v = y[c][g], one = V{} + T(1);
                const V sg = ((v > V{}) ? one : V{}) - ((v < V{}) ? one : V{});  // d|v|/dv, 0 at 0
                const V m = b.M[g] * sg;
                sums.c += m * v;
                yb[c][g] = in.cc * m;
              });
        }
      });
      if (!dw) continue;
      // An off-domain group whose points all satisfy L_S (rising outward, the usual case once
      // the network has learnt it) has yb = 0 in every lane: its reverse pass would only add
      // zeros to the accumulators, so it is skipped (the same gradient, bit for bit).
      if constexpr (OFF) {
        auto nz = yb[1][0] != V{};
        unroll<D>([&](auto i) { unroll<G>([&](auto g) { nz |= yb[1 + i][g] != V{}; }); });
        bool any = false;
        for (int l = 0; l < L; ++l) any = any || nz[l] != 0;
        if (!any) continue;
      }
      // Reverse: the output layer.
      {
        V* dWo = dw + S::woff(NH);
        for (int i = 0; i < NI; ++i) {
          V acc = dWo[i];
          unroll<C>([&](auto c) {
            unroll<G>([&](auto g) {
              acc += yb[c][g] * Al[(i * C + c) * G + g];
              b.Ab[(i * C + c) * G + g] = Wo[i] * yb[c][g];
            });
          });
          dWo[i] = acc;
        }
        V acc = dw[S::boff(NH)];
        unroll<G>([&](auto g) { acc += yb[0][g]; });
        dw[S::boff(NH)] = acc;
      }
      // The hidden layers, last to first.
      unroll<NH>([&](auto r) {
        constexpr int k = NH - 1 - r;  // hidden layer k: the output of weight layer k
        constexpr int NO = S::kWidth[k + 1];
        if constexpr (k >= 1) {
          constexpr int NIk = S::kWidth[k];
          sigmoid_back<NO, false>(b.A + aoff(k), b.Z + zoff(k), b.Ab, b.Zb);
          weight_grad<NIk, NO>(b.Zb, b.A + aoff(k - 1), dw + S::woff(k), dw + S::boff(k));
          backward_input<NIk, NO>(params + S::woff(k), b.Zb, b.Ab);
        } else {
          sigmoid_back<NO, true>(b.A, b.Z, b.Ab, b.Zb);
          V* dW = dw + S::woff(0);
          V* db = dw + S::boff(0);
          for (int o = 0; o < NO; ++o) {
            V acc = db[o];
            unroll<G>([&](auto g) { acc += b.Zb[(o * C) * G + g]; });
            db[o] = acc;
            unroll<D>([&](auto j) {
              V a = dW[o * D + j];
              unroll<G>([&](auto g) {
                a += b.Zb[(o * C) * G + g] * b.X[j * G + g];
                if constexpr (ORDER >= 1) a += b.Zb[(o * C + 1 + j) * G + g];
              });
              dW[o * D + j] = a;
            });
          }
        }
      });
    }
  }
};

}  // namespace yarnhom::cpu::epoch
