#pragma once
// The CPU training backend (the default): the cpu/ kernels, one OpenMP thread per network.
#include <memory>

#include "train/backend.hpp"

namespace yarnhom {

std::unique_ptr<Backend> make_cpu_backend();

}  // namespace yarnhom
