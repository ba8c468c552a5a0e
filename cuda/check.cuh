#pragma once
// CUDA error checks that throw yarnhom::cuda::CudaError naming the call and the CUDA error.
#include <cuda_runtime.h>

#include <string>

#include "cuda/api.hpp"

namespace yarnhom::cuda {

inline void check(cudaError_t e, const std::string& what) {
  if (e == cudaSuccess) return;
  std::string msg = "CUDA error in " + what + ": " + cudaGetErrorString(e);
  if (e == cudaErrorMemoryAllocation) msg += " (the GPU is out of memory)";
  if (e == cudaErrorNoDevice || e == cudaErrorInsufficientDriver)
    msg += " (the CUDA backend needs a GPU and a matching driver)";
  throw CudaError(msg);
}

}  // namespace yarnhom::cuda
