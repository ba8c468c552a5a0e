// The GPU's measured FP32 rate, the denominator of the benchmarks' "fraction of peak": every
// thread of a grid of several blocks per multiprocessor runs 8 independent FMA chains.
#include <cuda_runtime.h>

#include <algorithm>
#include <vector>

#include "cuda/api.hpp"
#include "cuda/check.cuh"

namespace yarnhom::cuda {
namespace {

constexpr int kChains = 8;

__global__ void fma_kernel(float* out, int iters, float a, float b) {
  float x[kChains];
#pragma unroll
  for (int c = 0; c < kChains; ++c) x[c] = threadIdx.x * 1e-3f + c;
  for (int i = 0; i < iters; ++i) {
#pragma unroll
    for (int c = 0; c < kChains; ++c) x[c] = fmaf(x[c], a, b);
  }
  float s = 0;
#pragma unroll
  for (int c = 0; c < kChains; ++c) s += x[c];
  if (s == 12345.678f) out[0] = s;  // keeps the chains alive
}

}  // namespace

double measure_fp32_peak() {
  int dev = 0, sms = 0;
  check(cudaGetDevice(&dev), "cudaGetDevice");
  check(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, dev), "cudaDeviceGetAttribute");
  DeviceVec<float> out(1);
  const int threads = 512, blocks = sms * 4, iters = 1 << 16;
  fma_kernel<<<blocks, threads>>>(out.data(), 256, 0.999f, 1e-4f);  // warm-up
  check(cudaGetLastError(), "launch of the FMA peak kernel");
  std::vector<double> ms;
  EventTimer t;
  for (int r = 0; r < 7; ++r) {
    t.start();
    fma_kernel<<<blocks, threads>>>(out.data(), iters, 0.999f, 1e-4f);
    ms.push_back(t.stop_ms());
  }
  std::sort(ms.begin(), ms.end());
  const double flops = 2.0 * kChains * double(iters) * threads * blocks;
  return flops / (ms[ms.size() / 2] * 1e-3);
}

}  // namespace yarnhom::cuda
