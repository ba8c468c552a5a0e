#pragma once
// The sigmoid applied to a jet, and its reverse mode; see cpu/mlp_jet.hpp for the formulas.
// Z, A, Abar, Zbar are [n, C*B] with channel c of point p in column c*B + p. The sigmoid
// itself is evaluated by Eigen's vectorized exp over the whole value block; the chain rule is
// a loop over neurons (contiguous) with d and the order fixed at compile time, so that the
// compiler unrolls the channel algebra and vectorizes across neurons.
#include <Eigen/Dense>
#include <utility>

#include "core/jet_layout.hpp"

namespace yarnhom::cpu {

namespace detail {

// Calls f(std::integral_constant<int, I>{}) for I = 0..N-1: a loop unrolled by the language,
// so every channel index below is a compile-time constant, the per-neuron channel arrays
// live in registers, and the loop over neurons vectorizes. (With plain loops and unroll
// pragmas GCC 12 left the d = 2, third-order reverse loop scalar: 20x slower.)
template <int N, class F>
inline void static_for(F&& f) {
  [&]<int... I>(std::integer_sequence<int, I...>) {
    (f(std::integral_constant<int, I>{}), ...);
  }(std::make_integer_sequence<int, N>{});
}

template <class T>
using MatT = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;

template <class T>
inline void sigmoid_values(const MatT<T>& Z, int B, MatT<T>& S0) {
  S0.resize(Z.rows(), B);
  S0.array() = (T(1) + (-Z.leftCols(B).array()).exp()).inverse();
}

template <class T, int D, int ORDER>
void sigmoid_jet_forward_impl(int B, const MatT<T>& Z, const MatT<T>& S0, MatT<T>& A) {
  constexpr int C = jet_channels(D, ORDER);
  const int n = static_cast<int>(Z.rows());
  const long stride = long(B) * n;  // distance between channel blocks
  for (int p = 0; p < B; ++p) {
    const T* zp = Z.data() + long(p) * n;
    const T* sp = S0.data() + long(p) * n;
    T* ap = A.data() + long(p) * n;
#pragma GCC ivdep
    for (int r = 0; r < n; ++r) {
      T z[C];
      static_for<C>([&](auto c) { z[c] = zp[c * stride + r]; });
      const T s0 = sp[r];
      const T s1 = s0 * (T(1) - s0);
      const T s2 = s1 * (T(1) - T(2) * s0);
      const T s3 = s1 * (T(1) - T(6) * s0 + T(6) * s0 * s0);
      ap[r] = s0;
      if constexpr (ORDER >= 1) static_for<D>([&](auto i) { ap[(1 + i) * stride + r] = s1 * z[1 + i]; });
      if constexpr (ORDER >= 2)
        static_for<jet_num_pairs(D)>([&](auto q) {
          constexpr JetPair e = jet_pair(D, q);
          constexpr int c = jet_first(D, 2) + q;
          ap[c * stride + r] = s2 * z[1 + e.i] * z[1 + e.j] + s1 * z[c];
        });
      if constexpr (ORDER >= 3)
        static_for<jet_num_triples(D)>([&](auto t) {
          constexpr JetTriple e = jet_triple(D, t);
          constexpr int c = jet_first(D, 3) + t;
          constexpr int cij = jet_ch2(D, e.i, e.j), cik = jet_ch2(D, e.i, e.k), cjk = jet_ch2(D, e.j, e.k);
          const T zi = z[1 + e.i], zj = z[1 + e.j], zk = z[1 + e.k];
          ap[c * stride + r] = s3 * zi * zj * zk + s2 * (z[cij] * zk + z[cik] * zj + z[cjk] * zi) + s1 * z[c];
        });
    }
  }
}

// Reverse mode: every product in the forward formulas sends its adjoint to each factor,
// and every s_n(z0) sends a_bar * (its coefficient) * s_{n+1} to z0.
template <class T, int D, int ORDER>
void sigmoid_jet_backward_impl(int B, const MatT<T>& Z, const MatT<T>& S0, const MatT<T>& Abar,
                               MatT<T>& Zbar) {
  constexpr int C = jet_channels(D, ORDER);
  const int n = static_cast<int>(Z.rows());
  const long stride = long(B) * n;
  for (int p = 0; p < B; ++p) {
    const T* zp = Z.data() + long(p) * n;
    const T* sp = S0.data() + long(p) * n;
    const T* abp = Abar.data() + long(p) * n;
    T* zbp = Zbar.data() + long(p) * n;
#pragma GCC ivdep
    for (int r = 0; r < n; ++r) {
      T z[C], ab[C], zb[C];
      static_for<C>([&](auto c) {
        z[c] = zp[c * stride + r];
        ab[c] = abp[c * stride + r];
      });
      const T s0 = sp[r];
      const T s1 = s0 * (T(1) - s0);
      const T s2 = s1 * (T(1) - T(2) * s0);
      const T s3 = s1 * (T(1) - T(6) * s0 + T(6) * s0 * s0);
      const T s4 = s1 * (T(1) - T(2) * s0) * (T(1) - T(12) * s0 + T(12) * s0 * s0);
      // Every channel c >= 0 of a has the term s1 * z_c (channel 0: a = s0, d/dz0 = s1).
      static_for<C>([&](auto c) { zb[c] = ab[c] * s1; });
      if constexpr (ORDER >= 1) static_for<D>([&](auto i) { zb[0] += ab[1 + i] * s2 * z[1 + i]; });
      if constexpr (ORDER >= 2)
        static_for<jet_num_pairs(D)>([&](auto q) {
          constexpr JetPair e = jet_pair(D, q);
          constexpr int c = jet_first(D, 2) + q;
          const T g = ab[c];
          zb[0] += g * (s3 * z[1 + e.i] * z[1 + e.j] + s2 * z[c]);
          zb[1 + e.i] += g * s2 * z[1 + e.j];
          zb[1 + e.j] += g * s2 * z[1 + e.i];
        });
      if constexpr (ORDER >= 3)
        static_for<jet_num_triples(D)>([&](auto t) {
          constexpr JetTriple e = jet_triple(D, t);
          constexpr int c = jet_first(D, 3) + t;
          constexpr int cij = jet_ch2(D, e.i, e.j), cik = jet_ch2(D, e.i, e.k), cjk = jet_ch2(D, e.j, e.k);
          const T g = ab[c];
          const T zi = z[1 + e.i], zj = z[1 + e.j], zk = z[1 + e.k];
          const T zij = z[cij], zik = z[cik], zjk = z[cjk];
          zb[0] += g * (s4 * zi * zj * zk + s3 * (zij * zk + zik * zj + zjk * zi) + s2 * z[c]);
          zb[1 + e.i] += g * (s3 * zj * zk + s2 * zjk);
          zb[1 + e.j] += g * (s3 * zi * zk + s2 * zik);
          zb[1 + e.k] += g * (s3 * zi * zj + s2 * zij);
          zb[cij] += g * s2 * zk;
          zb[cik] += g * s2 * zj;
          zb[cjk] += g * s2 * zi;
        });
      static_for<C>([&](auto c) { zbp[c * stride + r] = zb[c]; });
    }
  }
}

template <class T>
inline MatT<T>& scratch_s0() {
  thread_local MatT<T> s0;
  return s0;
}

}  // namespace detail

template <class T>
void sigmoid_jet_forward(int d, int order, int B, const detail::MatT<T>& Z, detail::MatT<T>& A) {
  A.resize(Z.rows(), Z.cols());
  auto& S0 = detail::scratch_s0<T>();
  detail::sigmoid_values(Z, B, S0);
#define YH_CASE(D, O)                                             \
  if (d == D && order == O) {                                     \
    detail::sigmoid_jet_forward_impl<T, D, O>(B, Z, S0, A);       \
    return;                                                       \
  }
  YH_CASE(1, 0) YH_CASE(1, 1) YH_CASE(1, 2) YH_CASE(1, 3)
  YH_CASE(2, 0) YH_CASE(2, 1) YH_CASE(2, 2) YH_CASE(2, 3)
#undef YH_CASE
}

template <class T>
void sigmoid_jet_backward(int d, int order, int B, const detail::MatT<T>& Z,
                          const detail::MatT<T>& Abar, detail::MatT<T>& Zbar) {
  Zbar.resize(Z.rows(), Z.cols());
  auto& S0 = detail::scratch_s0<T>();
  detail::sigmoid_values(Z, B, S0);
#define YH_CASE(D, O)                                                    \
  if (d == D && order == O) {                                            \
    detail::sigmoid_jet_backward_impl<T, D, O>(B, Z, S0, Abar, Zbar);    \
    return;                                                              \
  }
  YH_CASE(1, 0) YH_CASE(1, 1) YH_CASE(1, 2) YH_CASE(1, 3)
  YH_CASE(2, 0) YH_CASE(2, 1) YH_CASE(2, 2) YH_CASE(2, 3)
#undef YH_CASE
}

}  // namespace yarnhom::cpu
