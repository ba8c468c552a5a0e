// Twin of cpu::adam_update (cpu/adam.hpp): PyTorch Adam, one thread per parameter, written
// with __fmul_rn/__fadd_rn (no FMA contraction); the bias corrections in double on the host.
#include <cuda_runtime.h>

#include <cmath>
#include <cstdint>

#include "cpu/adam.hpp"
#include "cuda/adam.cuh"
#include "cuda/api.hpp"
#include "cuda/check.cuh"

namespace yarnhom::cuda {

namespace {

// PyTorch Adam without contraction into FMAs, so that it rounds like cpu::adam_update.
__global__ void adam_kernel(float* p, const float* g, float* m, float* v, int n, float b1, float b2, float one_b1,
                            float one_b2, float eps, float step_size, float bc2_sqrt) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  detail::adam_step(p[i], m[i], v[i], g[i], b1, b2, one_b1, one_b2, eps, step_size, bc2_sqrt);
}

}  // namespace

void adam_update(float* p, const float* g, float* m, float* v, int n, const cpu::AdamParams& a, int64_t step) {
  if (n <= 0) return;
  const double bc1 = 1.0 - std::pow(a.beta1, double(step));
  const double bc2 = 1.0 - std::pow(a.beta2, double(step));
  const int T = 256;
  adam_kernel<<<(n + T - 1) / T, T>>>(p, g, m, v, n, float(a.beta1), float(a.beta2), float(1.0 - a.beta1),
                                      float(1.0 - a.beta2), float(a.eps), float(a.lr / bc1),
                                      float(std::sqrt(bc2)));
  check(cudaGetLastError(), "launch of the Adam kernel");
}

}  // namespace yarnhom::cuda
