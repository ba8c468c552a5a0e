#pragma once
// The inverse of a symmetric positive definite 3 x 3 block (row-major, 9 doubles), through its
// Cholesky factor: A = L L^T, A^-1 = L^-T L^-1. The block-Jacobi preconditioner's blocks, built
// by the same arithmetic on the CPU (numerics/block_jacobi_pcg.cpp) and on the GPU
// (cuda/block_jacobi_pcg.cu, where it compiles as a device function). No Eigen: the .cu files
// include it.
#ifdef __CUDACC__
#define YARNHOM_HOST_DEVICE __host__ __device__
#else
#define YARNHOM_HOST_DEVICE
#endif
#include <math.h>

namespace yarnhom::numerics {

// Writes A^-1 to out (may be a); false (out untouched) when a pivot is not positive (or NaN):
// A is not positive definite. Reads the lower triangle of a.
YARNHOM_HOST_DEVICE inline bool spd3_inverse(const double* a, double* out) {
  const double a00 = a[0], a10 = a[3], a11 = a[4], a20 = a[6], a21 = a[7], a22 = a[8];
  if (!(a00 > 0)) return false;
  const double l00 = sqrt(a00), l10 = a10 / l00, l20 = a20 / l00;
  const double d1 = a11 - l10 * l10;
  if (!(d1 > 0)) return false;
  const double l11 = sqrt(d1), l21 = (a21 - l20 * l10) / l11;
  const double d2 = a22 - l20 * l20 - l21 * l21;
  if (!(d2 > 0)) return false;
  const double l22 = sqrt(d2);
  // M = L^-1 (lower), then A^-1 = M^T M.
  const double m00 = 1 / l00, m11 = 1 / l11, m22 = 1 / l22;
  const double m10 = -l10 * m00 * m11, m21 = -l21 * m11 * m22, m20 = -(l20 * m00 + l21 * m10) * m22;
  const double i00 = m00 * m00 + m10 * m10 + m20 * m20, i01 = m10 * m11 + m20 * m21, i02 = m20 * m22;
  const double i11 = m11 * m11 + m21 * m21, i12 = m21 * m22, i22 = m22 * m22;
  out[0] = i00, out[1] = i01, out[2] = i02;
  out[3] = i01, out[4] = i11, out[5] = i12;
  out[6] = i02, out[7] = i12, out[8] = i22;
  return true;
}

}  // namespace yarnhom::numerics
