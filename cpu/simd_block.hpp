// What the fused CPU kernels (cpu/polish_kernel.cpp, cpu/epoch_kernel_impl.hpp) share: a vector
// of 64 bytes as GCC's vector extension, and loops unrolled at compile time so that register
// blocks of accumulators have constant indices.
#pragma once

#include <utility>

namespace yarnhom::cpu::simd {

// f(integral_constant<I>) for I = 0..N-1: loops unrolled by the language, so the accumulator
// arrays have constant indices and live in registers.
template <int N, class F>
inline void unroll(F&& f) {
  [&]<int... I>(std::integer_sequence<int, I...>) { (f(std::integral_constant<int, I>{}), ...); }(
      std::make_integer_sequence<int, N>{});
}

// One 64-byte vector: 16 floats or 8 doubles (L lanes).
template <class T>
struct Simd {
  typedef T V __attribute__((vector_size(64)));
  static constexpr int L = 64 / int(sizeof(T));
};

}  // namespace yarnhom::cpu::simd
