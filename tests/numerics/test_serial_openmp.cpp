// numerics/serial_openmp.hpp: inside the scope every parallel region runs on one thread, even one
// that asks for more with num_threads (as CHOLMOD's do); outside it, OpenMP is as it was.
#include <gtest/gtest.h>
#include <omp.h>

#include "numerics/serial_openmp.hpp"

namespace {

int team_size_of_a_region_asking_for(int n) {
  int size = 0;
#pragma omp parallel num_threads(n)
  {
#pragma omp single
    size = omp_get_num_threads();
  }
  return size;
}

}  // namespace

TEST(SerialOpenMP, RegionsInsideTheScopeRunOnOneThreadAndTheSettingIsRestored) {
  const int levels = omp_get_max_active_levels();
  ASSERT_GT(levels, 0);
  ASSERT_EQ(team_size_of_a_region_asking_for(3), 3) << "OpenMP gives a team of 3 outside the scope";
  {
    const yarnhom::numerics::SerialOpenMP serial;
    EXPECT_EQ(team_size_of_a_region_asking_for(4), 1);
    {
      const yarnhom::numerics::SerialOpenMP nested;  // scopes nest
      EXPECT_EQ(team_size_of_a_region_asking_for(4), 1);
    }
    EXPECT_EQ(team_size_of_a_region_asking_for(4), 1);
  }
  EXPECT_EQ(omp_get_max_active_levels(), levels);
  EXPECT_EQ(team_size_of_a_region_asking_for(3), 3);
}
