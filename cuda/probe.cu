// mma_tf32_probe (cuda/api.hpp): one warp-level m16n8k8 TF32 MMA, one TF32 product or the
// 3xTF32 split, its fragments loaded and stored by the layout the tensor-core warp path
// (cuda/mma_jet.cuh) relies on; the test CudaMma.FragmentLayoutAnd3xTf32 checks it.
#include <cuda_runtime.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "cuda/api.hpp"
#include "cuda/check.cuh"
#include "cuda/mma_tf32.cuh"

namespace yarnhom::cuda {

using namespace detail;

namespace {

// One m16n8k8 TF32 MMA of a single warp, fragments by the documented layout (mma_tf32_probe).
__global__ void mma_probe_kernel(const float* A, const float* B, float* Dm, int three) {
  const int lane = threadIdx.x, g = lane >> 2, t = lane & 3;
  const float a0 = A[g * 8 + t], a1 = A[(g + 8) * 8 + t], a2 = A[g * 8 + t + 4], a3 = A[(g + 8) * 8 + t + 4];
  const float b0 = B[t * 8 + g], b1 = B[(t + 4) * 8 + g];
  float4 d = make_float4(0.f, 0.f, 0.f, 0.f);
  if (three) {
    const Tf32x4 a = split4(a0, a1, a2, a3);
    uint32_t b0b, b0s, b1b, b1s;
    split_tf32(b0, b0b, b0s);
    split_tf32(b1, b1b, b1s);
    mma3(d, a, b0b, b1b, b0s, b1s);
  } else {
    const uint32_t a[4] = {__float_as_uint(a0), __float_as_uint(a1), __float_as_uint(a2), __float_as_uint(a3)};
    mma_tf32(d, a, __float_as_uint(b0), __float_as_uint(b1));
  }
  Dm[g * 8 + 2 * t] = d.x;
  Dm[g * 8 + 2 * t + 1] = d.y;
  Dm[(g + 8) * 8 + 2 * t] = d.z;
  Dm[(g + 8) * 8 + 2 * t + 1] = d.w;
}

}  // namespace

std::vector<float> mma_tf32_probe(const std::vector<float>& a, const std::vector<float>& b, bool three) {
  if (a.size() != 128 || b.size() != 64) throw std::invalid_argument("mma_tf32_probe: A is 16x8, B 8x8");
  DeviceVec<float> da(a), db(b), dd(128);
  mma_probe_kernel<<<1, 32>>>(da.data(), db.data(), dd.data(), three ? 1 : 0);
  check(cudaGetLastError(), "launch of the MMA probe kernel");
  return dd.download();
}

}  // namespace yarnhom::cuda
