// set_blas_threads (numerics/blas_threads.hpp): with OpenBLAS behind the system BLAS, the thread
// count it asks for is the one OpenBLAS then reports, and blas_description says so; with another
// BLAS nothing is called and it returns false. blas_kernels_to_request: nothing while the user
// chose (OPENBLAS_CORETYPE); on an AMD CPU that OpenBLAS gave an AVX-512 set, its "Zen" set; a
// set that is right already, nothing.
#include <gtest/gtest.h>
#include <dlfcn.h>

#include <cstdlib>
#include <string>

#include "numerics/blas_threads.hpp"

using yarnhom::numerics::blas_description;
using yarnhom::numerics::blas_kernels_to_request;
using yarnhom::numerics::set_blas_threads;

TEST(BlasThreads, SetsOpenBlasWhenItIsTheBlas) {
  using GetThreads = int (*)();
  auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!get) {
    EXPECT_FALSE(set_blas_threads(1)) << "no OpenBLAS loaded, yet it claims to have set its threads";
    EXPECT_NE(std::string(blas_description()).find("reference BLAS"), std::string::npos) << blas_description();
    return;
  }
  EXPECT_FALSE(set_blas_threads(0));
  EXPECT_TRUE(set_blas_threads(2));
  EXPECT_EQ(get(), 2);
  EXPECT_NE(std::string(blas_description()).find("2 thread(s)"), std::string::npos) << blas_description();
  EXPECT_TRUE(set_blas_threads(1));
  EXPECT_EQ(get(), 1);
  EXPECT_NE(std::string(blas_description()).find("OpenBLAS"), std::string::npos) << blas_description();
}

TEST(BlasThreads, KernelsToRequestFollowTheCpuUnlessTheUserChose) {
  using Corename = char* (*)();
  auto corename = reinterpret_cast<Corename>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  const char* chosen = std::getenv("OPENBLAS_CORETYPE");
  if (!corename || chosen) {
    EXPECT_EQ(blas_kernels_to_request(), nullptr) << (chosen ? "OPENBLAS_CORETYPE is set" : "no OpenBLAS");
    return;
  }
  setenv("OPENBLAS_CORETYPE", "Haswell", 1);
  EXPECT_EQ(blas_kernels_to_request(), nullptr) << "a user's choice is overridden";
  unsetenv("OPENBLAS_CORETYPE");
  const std::string core = corename();
  const char* asked = blas_kernels_to_request();
  __builtin_cpu_init();
  const bool amd = __builtin_cpu_is("amd"), avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (core == "Zen" || core == "Haswell" || (core == "SkylakeX" && !amd)) {
    EXPECT_EQ(asked, nullptr) << core << " is right already, yet it asks for " << asked;
  }
  if (amd && avx2 && (core == "SkylakeX" || core == "Cooperlake" || core == "SapphireRapids")) {
    ASSERT_NE(asked, nullptr) << "an AMD CPU left with OpenBLAS's " << core << " kernels";
    EXPECT_EQ(std::string(asked), "Zen");
  }
  if (avx2 && (core == "Prescott" || core == "Core2" || core == "Nehalem" || core == "unknown")) {
    EXPECT_NE(asked, nullptr) << "an AVX2 CPU left with the fallback " << core;
  }
}
