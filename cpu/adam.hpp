#pragma once
// Adam with PyTorch's exact semantics (torch.optim.Adam, weight_decay 0, amsgrad off), one
// step over a flat parameter vector. `step` is the 1-based step count after this update.
//   m <- b1 m + (1 - b1) g
//   v <- b2 v + (1 - b2) g^2
//   p <- p - (lr / (1 - b1^t)) * m / (sqrt(v) / sqrt(1 - b2^t) + eps)
// The bias corrections are computed in double, as PyTorch does with Python floats.
#include <cmath>
#include <cstdint>

namespace yarnhom::cpu {

struct AdamParams {
  double lr = 1e-3, beta1 = 0.9, beta2 = 0.999, eps = 1e-8;
};

template <class T>
void adam_update(T* p, const T* g, T* m, T* v, int n, const AdamParams& a, int64_t step) {
  const double bc1 = 1.0 - std::pow(a.beta1, double(step));
  const double bc2 = 1.0 - std::pow(a.beta2, double(step));
  const T step_size = T(a.lr / bc1);
  const T bc2_sqrt = T(std::sqrt(bc2));
  const T b1 = T(a.beta1), b2 = T(a.beta2), eps = T(a.eps);
  const T one_b1 = T(1.0 - a.beta1), one_b2 = T(1.0 - a.beta2);
  for (int i = 0; i < n; ++i) {
    m[i] = m[i] * b1 + one_b1 * g[i];
    v[i] = v[i] * b2 + one_b2 * g[i] * g[i];
    const T denom = std::sqrt(v[i]) / bc2_sqrt + eps;
    p[i] -= step_size * (m[i] / denom);
  }
}

}  // namespace yarnhom::cpu
