// set_blas_threads (numerics/blas_threads.hpp): with OpenBLAS behind the system BLAS, the thread
// count it asks for is the one OpenBLAS then reports, and blas_description says so; with another
// BLAS nothing is called and it returns false.
#include <gtest/gtest.h>
#include <dlfcn.h>

#include <string>

#include "numerics/blas_threads.hpp"

using yarnhom::numerics::blas_description;
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
