#pragma once
// cpu::adam_update (cpu/adam.hpp) for float in 16-wide vectors: the CPU backend's step after
// every minibatch. The scalar loop does not vectorize (std::sqrt may set errno, so GCC keeps it
// a scalar call): after the epochs' fused kernel (cpu/epoch_kernel.hpp) it was 6 % of a
// paper-recipe run. Same formulas, in the same order, with the vector square root (correctly
// rounded, as the scalar one); the tail past a multiple of 16 runs the scalar formulas.
#include <cmath>
#include <cstdint>
#if defined(__AVX512F__) || defined(__AVX__)
#include <immintrin.h>
#endif

#include "cpu/adam.hpp"

namespace yarnhom::cpu {

inline void adam_update_simd(float* p, const float* g, float* m, float* v, int n, const AdamParams& a,
                             int64_t step) {
  const double bc1 = 1.0 - std::pow(a.beta1, double(step));
  const double bc2 = 1.0 - std::pow(a.beta2, double(step));
  const float step_size = float(a.lr / bc1);
  const float bc2_sqrt = float(std::sqrt(bc2));
  const float b1 = float(a.beta1), b2 = float(a.beta2), eps = float(a.eps);
  const float one_b1 = float(1.0 - a.beta1), one_b2 = float(1.0 - a.beta2);
  int i = 0;
#if defined(__AVX512F__)
  typedef float V __attribute__((vector_size(64)));
  for (; i + 16 <= n; i += 16) {
    V pv, gv, mv, vv;
    __builtin_memcpy(&pv, p + i, 64);
    __builtin_memcpy(&gv, g + i, 64);
    __builtin_memcpy(&mv, m + i, 64);
    __builtin_memcpy(&vv, v + i, 64);
    mv = mv * b1 + one_b1 * gv;
    vv = vv * b2 + one_b2 * gv * gv;
    const V root = V(_mm512_sqrt_ps(__m512(vv)));
    const V denom = root / bc2_sqrt + eps;
    pv -= step_size * (mv / denom);
    __builtin_memcpy(p + i, &pv, 64);
    __builtin_memcpy(m + i, &mv, 64);
    __builtin_memcpy(v + i, &vv, 64);
  }
#endif
  for (; i < n; ++i) {
    m[i] = m[i] * b1 + one_b1 * g[i];
    v[i] = v[i] * b2 + one_b2 * g[i] * g[i];
    const float denom = std::sqrt(v[i]) / bc2_sqrt + eps;
    p[i] -= step_size * (m[i] / denom);
  }
}

}  // namespace yarnhom::cpu
