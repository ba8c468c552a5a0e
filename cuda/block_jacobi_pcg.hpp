#pragma once
// The GPU twin of numerics/block_jacobi_pcg.hpp: block-Jacobi preconditioned conjugate gradients
// in double on the device, the same steps in the same order as the CPU twin (the sums' order
// differs: warp and block reductions), for the continuum simulator's `--solver pcg-cuda`.
// Plain C++ (no CUDA headers). Errors throw cuda::CudaError naming the call.
#include <memory>

#include "numerics/pcg_system.hpp"

namespace yarnhom::cuda {

// A new GPU solver (throws CudaError without a usable GPU). numerics::register_pcg_device takes
// this function.
std::unique_ptr<numerics::PcgDevice> make_pcg_device();

}  // namespace yarnhom::cuda
