// Issue 34: `mpirun -np N yarnhom produce` writes the one-process dataset bit for bit, and a run
// whose rank dies resumes with another number of ranks to the same dataset (docs/produce.md,
// "On a cluster"). Needs a build with MPI, mpirun, and the paper's tiny stockinette from
// ../shared/patterns; skips with a line saying which is missing.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

#include "core/dataset.hpp"
#include "tests/common/dataset_compare.hpp"
#include "tests/common/mpi_run.hpp"
#include "tests/common/process_tree.hpp"
#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;
using yarnhom::test::run_shell;

namespace {

using yarnhom::test::mpirun;
using yarnhom::test::slurp;

std::string stocktiny() { return yarnhom::test::mpi_stocktiny(); }
std::string tmpdir(const char* name) { return yarnhom::test::mpi_tmpdir("yarnhom_mpi", name); }

// A term of each kind, quick preset: 21 + 81 nodes, both passes.
std::string produce_args(const std::string& out) {
  return " produce " + stocktiny() + " --preset quick --terms 3,01 -o " + out;
}

size_t records_in(const std::string& checkpoint) {
  const std::string f = slurp(checkpoint);
  size_t n = 0;
  for (size_t at = f.find("YREC"); at != std::string::npos; at = f.find("YREC", at + 4)) ++n;
  return n;
}

// The MPI rank of a process (Open MPI puts it in the environment), -1 if none.
int rank_of(pid_t pid) {
  const std::string env = slurp("/proc/" + std::to_string(pid) + "/environ");
  const std::string key = std::string("OMPI_COMM_WORLD_RANK=");
  for (size_t at = 0; at < env.size(); at = env.find('\0', at) + 1) {
    if (env.compare(at, key.size(), key) == 0) return std::atoi(env.c_str() + at + key.size());
    if (env.find('\0', at) == std::string::npos) break;
  }
  return -1;
}

// From the summary's per-rank line: the first-pass tasks and the branch solves rank r ran.
std::pair<int, int> rank_work(const std::string& out, int r) {
  const std::string key = "  rank " + std::to_string(r) + " ";
  const size_t at = out.find(key);
  if (at == std::string::npos) return {-1, -1};
  int tasks = -1, jobs = -1;
  const size_t t = out.find(" tasks", at), j = out.find(" branch solves", at);
  if (t != std::string::npos) tasks = std::atoi(out.c_str() + out.rfind(' ', t - 1) + 1);
  if (j != std::string::npos) jobs = std::atoi(out.c_str() + out.rfind(' ', j - 1) + 1);
  return {tasks, jobs};
}

// From the summary: "K branch jobs solved ahead of their round, U used".
std::pair<int, int> ahead(const std::string& out) {
  const size_t at = out.find(" branch jobs solved ahead");
  if (at == std::string::npos) return {-1, -1};
  size_t b = out.rfind(' ', at - 1) + 1;
  const size_t u = out.find(", ", at);
  return {std::atoi(out.c_str() + b), u == std::string::npos ? -1 : std::atoi(out.c_str() + u + 2)};
}

}  // namespace

TEST(ProduceMpi, RanksWriteTheOneProcessDatasetAndARunWhoseRankDiedResumesWithOtherRanks) {
  if (const std::string why = yarnhom::test::mpi_skip_reason(2); !why.empty()) GTEST_SKIP() << why;
  const std::string d = tmpdir("ranks");

  auto one = yarnhom::test::run_cli(produce_args(d + "/one.h5") + " --threads 2");
  ASSERT_EQ(one.status, 0) << one.out;
  const yarnhom::Dataset ref = yarnhom::read_dataset(d + "/one.h5");

  // Three ranks, each solving (rank 0 also coordinates).
  auto three = run_shell(mpirun(3) + produce_args(d + "/three.h5"));
  ASSERT_EQ(three.status, 0) << three.out;
  EXPECT_NE(three.out.find("3 MPI ranks"), std::string::npos) << three.out;
  yarnhom::test::expect_identical(ref, yarnhom::read_dataset(d + "/three.h5"), "3 ranks");
  // The files themselves, byte for byte (no modification times in them: core/h5.cpp).
  EXPECT_TRUE(slurp(d + "/one.h5") == slurp(d + "/three.h5")) << "the files differ";

  // Two ranks: rank 0 coordinates and solves, and the branch rounds overlap (11 rounds here: the
  // next round's decided jobs are solved while a round's last job runs). The same bytes.
  const size_t rounds_at = one.out.find(" branch round(s)");
  ASSERT_NE(rounds_at, std::string::npos) << one.out;
  EXPECT_GE(std::atoi(one.out.c_str() + one.out.rfind(' ', rounds_at - 1) + 1), 2) << one.out;
  auto two = run_shell(mpirun(2) + produce_args(d + "/two.h5"));
  ASSERT_EQ(two.status, 0) << two.out;
  EXPECT_TRUE(slurp(d + "/one.h5") == slurp(d + "/two.h5")) << "the files differ (2 ranks)\n" << two.out;
  for (const auto& [out, ranks] : {std::pair{three.out, 3}, std::pair{two.out, 2}}) {
    const auto [tasks, jobs] = rank_work(out, 0);
    EXPECT_GT(tasks, 0) << "rank 0 solved no first-pass task on " << ranks << " ranks\n" << out;
    EXPECT_GT(jobs, 0) << "rank 0 solved no branch source on " << ranks << " ranks\n" << out;
    EXPECT_GT(rank_work(out, ranks - 1).second, 0) << out;
    const auto [solved, used] = ahead(out);
    EXPECT_GT(solved, 0) << "no branch job solved ahead of its round in 11 rounds on " << ranks << " ranks\n" << out;
    EXPECT_GE(used, 0) << out;
    EXPECT_LE(used, solved) << out;
  }

  // A rank killed mid-run: mpirun ends the run and names the rank; rank 0's checkpoint holds
  // what was finished, and two ranks take it up to the same dataset.
  const std::string log = d + "/killed.log", ck = d + "/killed.h5.partial";
  auto bg = run_shell("(" + mpirun(3) + produce_args(d + "/killed.h5") + " > " + log + " 2>&1 & echo $!)");
  const pid_t launcher = std::stoi(bg.out);
  const auto t0 = std::chrono::steady_clock::now();
  while (records_in(ck) < 12 && yarnhom::test::alive(launcher) &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_GE(records_in(ck), 12u) << slurp(log);
  pid_t victim = -1;
  for (pid_t p : yarnhom::test::descendants(launcher))
    if (rank_of(p) == 2) victim = p;
  ASSERT_GT(victim, 0) << "no rank 2 among mpirun's processes";
  ASSERT_EQ(::kill(victim, SIGKILL), 0);
  while (yarnhom::test::alive(launcher) && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(180))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_FALSE(yarnhom::test::alive(launcher)) << "mpirun did not end after its rank 2 was killed";
  const std::string killed_log = slurp(log);
  EXPECT_NE(killed_log.find("rank 2"), std::string::npos) << killed_log;
  EXPECT_FALSE(fs::exists(d + "/killed.h5")) << killed_log;

  auto resumed = run_shell(mpirun(2) + produce_args(d + "/killed.h5"));
  ASSERT_EQ(resumed.status, 0) << resumed.out;
  EXPECT_NE(resumed.out.find("resumed"), std::string::npos) << resumed.out;
  yarnhom::test::expect_identical(ref, yarnhom::read_dataset(d + "/killed.h5"), "killed at 3 ranks, resumed with 2");
  EXPECT_TRUE(slurp(d + "/one.h5") == slurp(d + "/killed.h5")) << "the files differ";
  fs::remove_all(d);
}
