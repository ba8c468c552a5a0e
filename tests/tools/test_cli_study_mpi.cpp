// Issue 34: `mpirun -np N yarnhom study ...` and `accuracy` run their independent pieces on the
// ranks (pipeline/rank_tasks.hpp) and write the files one process writes, running every stage
// once (docs/produce.md, "The studies on a cluster"). Needs a build with MPI, mpirun that can
// start 3 processes, and the paper's tiny stockinette from ../shared/patterns; skips with a line
// saying which is missing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/common/mpi_run.hpp"
#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;
using yarnhom::test::run_shell;

namespace {

using yarnhom::test::mpirun;
using yarnhom::test::slurp;

std::string stocktiny() { return yarnhom::test::mpi_stocktiny(); }
std::string tmpdir(const char* name) { return yarnhom::test::mpi_tmpdir("yarnhom_study_mpi", name); }
std::string skip_reason() { return yarnhom::test::mpi_skip_reason(3); }

// The stages a run's output says ran: "NAME (why)" per "  NAME running (why) ..." line, the
// run's folder in the reason replaced by DIR, sorted.
std::vector<std::string> stages_run(const std::string& out, const std::string& dir) {
  std::vector<std::string> v;
  const std::regex line(R"(^  (\S+) +running \((.*)\) \.\.\.)");
  std::istringstream in(out);
  for (std::string l; std::getline(in, l);) {
    std::smatch m;
    if (!std::regex_search(l, m, line)) continue;
    std::string why = m[2];
    for (size_t at; (at = why.find(dir)) != std::string::npos;) why.replace(at, dir.size(), "DIR");
    v.push_back(m[1].str() + " (" + why + ")");
  }
  std::sort(v.begin(), v.end());
  return v;
}

// Every rank's stage lines (DIR/logs/rank-R.log), and how many ranks ran a stage.
std::string rank_logs(const std::string& dir, int ranks, int* working) {
  std::string all;
  *working = 0;
  for (int r = 0; r < ranks; ++r) {
    const std::string log = slurp(dir + "/logs/rank-" + std::to_string(r) + ".log");
    EXPECT_FALSE(log.empty()) << "no log of rank " << r;
    if (log.find(" running (") != std::string::npos) ++*working;
    all += log;
  }
  return all;
}

// The study's files that one process writes deterministically, byte for byte.
void expect_same_files(const std::string& one, const std::string& three, const std::vector<std::string>& names) {
  for (const std::string& n : names) {
    ASSERT_TRUE(fs::exists(one + "/" + n)) << n;
    EXPECT_TRUE(slurp(one + "/" + n) == slurp(three + "/" + n)) << n << " differs between 1 process and 3 ranks";
  }
}

const char* kSmall =
    " --preset tiny --stretch 1.0:1.1:0.1 --epochs 20 --threads 1 --strip-args '--clamp 0.0009 --threads 1 --no-plots' "
    "--sim-args '--resolution 4 --threads 1'";

}  // namespace

// study strip-width: its widths share one dataset and one material (produce, train-all and bake
// run once, on some rank), each width has its yarn strip and its continuum strip. Then accuracy
// on that dataset and material: its yarn strip, spline fit and two continuum strips are
// independent pieces; again the one-process files. With --force every stage runs again, once
// (a stage forced earlier in the same run is not run again by the rank that comes to it next).
TEST(StudyMpi, StripWidthAndAccuracyOnThreeRanksWriteTheOneProcessFilesRunningEachStageOnce) {
  if (const std::string why = skip_reason(); !why.empty()) GTEST_SKIP() << why;
  const std::string d = tmpdir("study");
  const std::string args = " study strip-width " + stocktiny() + " --direction wale --widths 0.005,0.0035 --length 0.0027 --no-plot" + kSmall;
  const auto one = yarnhom::test::run_cli(args + " -o " + d + "/one");
  ASSERT_EQ(one.status, 0) << one.out;
  const auto three = run_shell(mpirun(3) + args + " -o " + d + "/three");
  ASSERT_EQ(three.status, 0) << three.out;
  EXPECT_NE(three.out.find("study strip-width on 3 ranks"), std::string::npos) << three.out;
  EXPECT_NE(three.out.find("(6 of 6 tasks)"), std::string::npos) << three.out;
  expect_same_files(d + "/one", d + "/three", {"width.csv", "width.md", "w_0.005/accuracy.csv", "w_0.0035/accuracy.csv"});
  // The same 7 stages ran (produce, train-all, bake, two yarn strips, two continuum strips), each
  // once, on at least two ranks; rank 0's single pass at the end found every one done.
  const auto want = stages_run(one.out, d + "/one");
  EXPECT_EQ(want.size(), 7u) << one.out;
  int working = 0;
  EXPECT_EQ(stages_run(rank_logs(d + "/three", 3, &working), d + "/three"), want);
  EXPECT_GE(working, 2) << three.out;
  EXPECT_TRUE(stages_run(three.out, d + "/three").empty()) << three.out;

  const std::string acc = " accuracy " + stocktiny() + " --direction wale --size 0.0035,0.0027 --dataset " + d +
                          "/one/dataset.h5 --baked " + d + "/one/neural.h5" + kSmall;
  const auto a1 = yarnhom::test::run_cli(acc + " -o " + d + "/a1");
  ASSERT_EQ(a1.status, 0) << a1.out;
  const auto a3 = run_shell(mpirun(3) + acc + " -o " + d + "/a3");
  ASSERT_EQ(a3.status, 0) << a3.out;
  expect_same_files(d + "/a1", d + "/a3", {"accuracy.csv"});
  const auto want_a = stages_run(a1.out, d + "/a1");
  EXPECT_EQ(want_a.size(), 4u) << a1.out;  // fit-splines, the yarn strip, two continuum strips
  EXPECT_EQ(stages_run(rank_logs(d + "/a3", 3, &working), d + "/a3"), want_a);
  EXPECT_GE(working, 2) << a3.out;

  for (int r = 0; r < 3; ++r) fs::remove(d + "/a3/logs/rank-" + std::to_string(r) + ".log");
  const auto forced = run_shell(mpirun(3) + acc + " --force -o " + d + "/a3");
  ASSERT_EQ(forced.status, 0) << forced.out;
  const auto ran = stages_run(rank_logs(d + "/a3", 3, &working), d + "/a3");
  ASSERT_EQ(ran.size(), want_a.size()) << forced.out;
  for (const std::string& s : ran) EXPECT_NE(s.find("(--force)"), std::string::npos) << s;
  EXPECT_TRUE(stages_run(forced.out, d + "/a3").empty()) << forced.out;
  expect_same_files(d + "/a1", d + "/a3", {"accuracy.csv"});
  fs::remove_all(d);
}
