#pragma once
// The CUDA training backend: the cuda/ kernels, every network in one launch sequence.
// Compiled only when the build has the CUDA backend (YARNHOM_HAVE_CUDA).
#include <memory>

#include "train/backend.hpp"

namespace yarnhom {

std::unique_ptr<Backend> make_cuda_backend();

}  // namespace yarnhom
