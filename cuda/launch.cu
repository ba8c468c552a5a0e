// The launch machinery of the multi-block twins (declared in cuda/launch.cuh): the launch
// shape, the device's limits, the choice of stride and blocks, the block-order reduction.
#include <cuda_runtime.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "cuda/api.hpp"
#include "cuda/check.cuh"
#include "cuda/launch.cuh"

namespace yarnhom::cuda {

namespace detail {
namespace {

LaunchShape g_shape;

// dst[i] (+)= sum over blocks b in order of partial[b*P + i].
__global__ void reduce_blocks_kernel(const float* partial, int blocks, int P, float* dst, int accumulate) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= P) return;
  float acc = partial[i];
  for (int b = 1; b < blocks; ++b) acc += partial[size_t(b) * P + i];
  dst[i] = accumulate ? dst[i] + acc : acc;
}

// A device attribute of the current device, read once per attribute by the caller's static.
int device_attribute(cudaDeviceAttr attr) {
  int dev = 0, v = 0;
  check(cudaGetDevice(&dev), "cudaGetDevice");
  check(cudaDeviceGetAttribute(&v, attr, dev), "cudaDeviceGetAttribute");
  return v;
}

}  // namespace

const LaunchShape& launch_shape() { return g_shape; }

int sm_count() {
  static int n = device_attribute(cudaDevAttrMultiProcessorCount);
  return n;
}

int smem_optin() {
  static int n = device_attribute(cudaDevAttrMaxSharedMemoryPerBlockOptin);
  return n;
}

Launch pick_launch(const NetShape& s, int tasks, bool with_grad) {
  Launch l;
  l.threads = g_shape.threads > 0 ? g_shape.threads : 512;
  l.S = g_shape.stride > 0 ? chunk_stride(g_shape.stride) : 228;  // fastest measured on the H200
  const int P4 = (s.P + 3) & ~3;
  const int base = with_grad ? 2 * P4 : P4;
  l.smem = size_t(chunk_layout(s, l.S, base).total) * sizeof(float);
  // A stride whose buffers exceed the block's shared-memory limit is lowered until they fit.
  while (l.smem > size_t(smem_optin()) && l.S > 36) {
    l.S -= 32;
    l.smem = size_t(chunk_layout(s, l.S, base).total) * sizeof(float);
  }
  if (l.smem > size_t(smem_optin()))
    throw std::invalid_argument("the network is too wide for the CUDA kernels' shared memory");
  const int per_sm = std::max(1, int((228 * 1024) / (l.smem + 1024)));
  const int want = g_shape.blocks > 0 ? g_shape.blocks : sm_count() * per_sm;
  l.blocks = std::max(1, std::min(tasks, want));
  return l;
}

void reduce_blocks(const float* partial, int blocks, int P, float* dst, bool accumulate) {
  reduce_blocks_kernel<<<(P + 255) / 256, 256>>>(partial, blocks, P, dst, accumulate ? 1 : 0);
  check(cudaGetLastError(), "launch of the gradient reduction kernel");
}

}  // namespace detail

void set_launch_shape(const LaunchShape& s) { detail::g_shape = s; }

}  // namespace yarnhom::cuda
