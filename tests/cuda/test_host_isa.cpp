// nvcc's host pass over the .cu files targets the same ISA, with the same compiler and
// floating-point model, as the .cpp files: a program linked from both must not hold two builds
// of one inline function or template (docs/layout.md, "Compiler flags"). Host code: runs
// without a GPU.
#include <gtest/gtest.h>

#include <string>

#include "core/host_isa.hpp"
#include "cuda/api.hpp"

TEST(CudaBuild, HostPassTargetsTheSameIsaAsTheCppFiles) {
  const std::string cpp = YARNHOM_HOST_ISA;
  EXPECT_EQ(yarnhom::cuda::host_isa(), cpp)
      << "the .cu files' host code was compiled for another target than the .cpp files";
}
