#pragma once
// The paper's losses on output jets (spec section 6), forward and adjoint, on the CPU.
// All are in normalized units. Each function returns the *unweighted* sums over its points
// (the caller divides by the batch size M or K, so that a batch split into chunks sums to the
// same loss), and, when djet is given, adds weight * scale * d(sum)/d(jet) into it.
//
//   L_Z = 1/M sum (y_hat - y)^2
//   L_F = 1/M sum |grad y_hat - grad y|^2
//   L_C = 1/M sum sum_{|alpha|=3} |d^alpha y_hat|      (4 distinct third derivatives in 2D)
//   L_X = 1/M sum relu(-lambda_min(hess y_hat))^2
//   L_S = 1/K sum relu(-grad y_hat(x_o) . n_o)^2       (off-domain points)
#include <cmath>

#include "core/jet_layout.hpp"
#include "core/network.hpp"

namespace yarnhom::cpu {

template <class T>
struct LossSums {
  T z = 0, f = 0, c = 0, s = 0, x = 0;
};

// jet: [C, B] channel-major output jet of B data points, order >= 1 (>= 2 for L_X, 3 for
// exact L_C). y: [B], g: [B, d]. wt: [B] weights of each point's L_Z and L_F residuals, or
// nullptr (all 1). djet: [C, B] adjoint (accumulated), or nullptr.
// scale multiplies the adjoint (1/M). Terms with zero weight are neither summed nor derived;
// with exact_c false, L_C is left to the stencil (cpu/loss_stencil.hpp).
template <class T>
LossSums<T> data_losses(int d, int B, int order, const T* jet, const T* y, const T* g, const T* wt,
                        const LossWeights& w, bool exact_c, T scale, T* djet);

// Strain concentration on K off-domain points. jet: [C, K] with order >= 1, normals: [K, d].
template <class T>
T strain_concentration_loss(int d, int K, int order, const T* jet, const T* normals, T weight_scale,
                            T* djet);

// The smallest eigenvalue of the symmetric 2x2 [[a, b], [b, c]] and its derivatives with
// respect to a, b, c (b counted once). At a double eigenvalue (r = 0) the derivative is the
// one of the mean (a + c)/2, a valid subgradient.
template <class T>
YH_HD inline T min_eigenvalue_2x2(T a, T b, T c, T* da, T* db, T* dc) {
  const T h = (a - c) / T(2);
  const T r2 = h * h + b * b;
  const T r = r2 > T(0) ? T(std::sqrt(r2)) : T(0);
  if (r > T(0)) {
    *da = T(0.5) - h / (T(2) * r);
    *dc = T(0.5) + h / (T(2) * r);
    *db = -b / r;
  } else {
    *da = *dc = T(0.5);
    *db = T(0);
  }
  return (a + c) / T(2) - r;
}

}  // namespace yarnhom::cpu
