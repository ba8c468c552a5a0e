// The downstream commands end to end: bake a trained model, evaluate the baked file beside the
// model with eval, measure it with error, and run the pipeline twice (the second run skips
// every stage).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;

using Result = yarnhom::test::CliResult;

namespace {

Result run(const std::string& args) { return yarnhom::test::run_cli(args); }

std::string tmpdir(const char* name) {
  fs::path d = fs::temp_directory_path() / ("yarnhom_e2e_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

// The numeric cells of the second CSV line (the first point).
std::vector<double> first_row(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, cell;
  std::getline(in, line);
  std::getline(in, line);
  std::vector<double> v;
  std::stringstream ls(line);
  while (std::getline(ls, cell, ',')) v.push_back(std::stod(cell));
  return v;
}

}  // namespace

TEST(CliBake, BakedFileReproducesTheModelAndErrorReportsIt) {
  const std::string d = tmpdir("bake");
  ASSERT_EQ(run("synth -o " + d + "/d.h5").status, 0);
  ASSERT_EQ(run("train-all " + d + "/d.h5 -o " + d + "/m.h5 --epochs 20 --terms 0,02 -q").status, 0);
  auto r = run("bake " + d + "/m.h5 -o " + d + "/b.h5");
  ASSERT_EQ(r.status, 0) << r.out;
  // The rest check is printed, naming the terms the model lacks (bake/rest_check.hpp).
  EXPECT_NE(r.out.find("\nrest: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("in-plane stress at rest"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("terms absent:"), std::string::npos) << r.out;
  // Inside the box the bicubic table agrees with the network to the interpolation error.
  auto m = run("eval " + d + "/m.h5 --term 02 --at 0.33,0.41");
  auto b = run("eval " + d + "/b.h5 --term 02 --at 0.33,0.41");
  ASSERT_EQ(m.status, 0) << m.out;
  ASSERT_EQ(b.status, 0) << b.out;
  auto vm = first_row(m.out), vb = first_row(b.out);
  ASSERT_GE(vb.size(), 5u);
  EXPECT_NEAR(vb[2], vm[2], 1e-5 * (1 + std::abs(vm[2])));  // psi
  EXPECT_NEAR(vb[3], vm[3], 1e-3 * (1 + std::abs(vm[3])));  // d/ds_x
  // Far outside the box the baked file answers (safeguard) with finite numbers.
  auto o = run("eval " + d + "/b.h5 --term 02 --at 3.0,-2.0");
  ASSERT_EQ(o.status, 0) << o.out;
  for (double x : first_row(o.out)) EXPECT_TRUE(std::isfinite(x));
  r = run("error " + d + "/b.h5 --data " + d + "/d.h5 --model " + d + "/m.h5 --samples 64");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("E (supplement Eq. 4"), std::string::npos) << r.out;
  fs::remove_all(d);
}

TEST(CliBake, PipelineRunsOnceAndSkipsFinishedStages) {
  const std::string d = tmpdir("pipeline");
  auto r = run("pipeline synthetic -o " + d + "/run --epochs 3 --recipe paper --no-plot");
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* f : {"dataset.h5", "model.h5", "baked.h5", "errors.txt"})
    EXPECT_TRUE(fs::exists(d + "/run/" + f)) << f;
  // The report says whether the material's rest is stable and stress free.
  EXPECT_NE(r.out.find("\n  rest: "), std::string::npos) << r.out;
  const auto t = fs::last_write_time(d + "/run/model.h5");
  r = run("pipeline synthetic -o " + d + "/run --epochs 3 --recipe paper --no-plot");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(fs::last_write_time(d + "/run/model.h5"), t) << "train-all must not rerun";
  // A changed setting reruns training.
  r = run("pipeline synthetic -o " + d + "/run --epochs 4 --recipe paper --no-plot");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(fs::last_write_time(d + "/run/model.h5"), t);
  fs::remove_all(d);
}
