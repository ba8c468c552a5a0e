// The accuracy study's commands end to end: fit-splines on a dataset, its baked file read back by
// eval (inside the knots and in the linear extrapolation).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

std::string tmpdir(const char* name) {
  fs::path d = fs::temp_directory_path() / ("yarnhom_acc_e2e_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

// The numeric rows of eval's CSV output.
std::vector<std::vector<double>> rows(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::vector<double>> out;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ls(line);
    while (std::getline(ls, cell, ',')) v.push_back(std::stod(cell));
    out.push_back(v);
  }
  return out;
}

}  // namespace

TEST(CliAccuracy, FitSplinesWritesABakedFileThatEvalReads) {
  const std::string d = tmpdir("fit");
  ASSERT_EQ(yarnhom::test::run_cli("synth -o " + d + "/d.h5").status, 0);
  auto r = yarnhom::test::run_cli("fit-splines " + d + "/d.h5 -o " + d + "/s.h5");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("fitted 14 terms"), std::string::npos) << r.out;
  // Term 0 at 0 (a knot, constrained to 0), inside, and far outside (linear: no curvature).
  auto e = yarnhom::test::run_cli("eval " + d + "/s.h5 --term 0 --at 0 --at 0.3 --at 5");
  ASSERT_EQ(e.status, 0) << e.out;
  auto v = rows(e.out);
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0][1], 0.0);               // psi(0) = 0
  EXPECT_GT(v[1][1], 0.0);               // stretching costs energy
  EXPECT_TRUE(std::isfinite(v[2][1]));
  EXPECT_GE(v[2][2], 0.0);               // the extrapolation rises outward
  EXPECT_EQ(v[2][3], 0.0);               // and is linear there
  // A 2D term evaluates too.
  auto e2 = yarnhom::test::run_cli("eval " + d + "/s.h5 --term 02 --at 0.2,0.3");
  EXPECT_EQ(e2.status, 0) << e2.out;
  // Bad input is refused with the option named.
  auto bad = yarnhom::test::run_cli("fit-splines " + d + "/d.h5 -o " + d + "/t.h5 --knots1d 2");
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.out.find("knots1d"), std::string::npos) << bad.out;
  fs::remove_all(d);
}
