// cuda::host_isa() (cuda/api.hpp): the target ISA of nvcc's host pass over the .cu files, for
// tests/cuda/test_host_isa.cpp to compare with the .cpp files' (docs/layout.md, "Compiler flags").
#include <string>

#include "core/host_isa.hpp"
#include "cuda/api.hpp"

namespace yarnhom::cuda {

std::string host_isa() { return YARNHOM_HOST_ISA; }

}  // namespace yarnhom::cuda
