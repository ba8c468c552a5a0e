// The stage runner's claims (pipeline/stage_runner.hpp): --force runs a stage once per run (the
// ranks of one mpirun share a run id), and a stage another process holds is waited for, then
// found done. The "stage" here is this test program run with a filter that selects no test.
#include <gtest/gtest.h>
#include <sys/file.h>
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "pipeline/rank_tasks.hpp"
#include "pipeline/stage_runner.hpp"

using namespace yarnhom::pipeline;
namespace fs = std::filesystem;

TEST(StageRunner, ForceRunsAStageOncePerRunAndALockedStageIsWaitedFor) {
  const fs::path dir = fs::temp_directory_path() / ("yarnhom_stage_runner_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = (dir / "out.txt").string();
  std::ofstream(out) << "x";
  const StageSpec s = {"noop", {"--gtest_filter=-*"}, {}, {out}};
  EXPECT_TRUE(run_stage(dir, s, false).ran);  // no record yet
  EXPECT_FALSE(run_stage(dir, s, false).ran);
  // --force: once in this run, again in another.
  set_stage_run_id("run A");
  EXPECT_TRUE(run_stage(dir, s, true).ran);
  EXPECT_FALSE(run_stage(dir, s, true).ran);
  set_stage_run_id("run B");
  EXPECT_TRUE(run_stage(dir, s, true).ran);

  // Another holder of the stage's lock: the runner waits (calling the wait hook meanwhile),
  // and runs the stage only once the lock is free.
  fs::remove(dir / ".stages" / "noop.done");
  const int fd = ::open((dir / ".stages" / "noop.lock").c_str(), O_RDWR);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  std::atomic<int> hooks{0};
  set_stage_wait_hook([&hooks] { ++hooks; });
  std::atomic<bool> done{false}, ran{false};
  std::thread t([&] {
    ran = run_stage(dir, s, false).ran;
    done = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  EXPECT_FALSE(done) << "ran a stage whose lock another holder had";
  EXPECT_GE(hooks.load(), 2);
  ::close(fd);  // releases the lock
  t.join();
  set_stage_wait_hook(nullptr);
  EXPECT_TRUE(ran);
  EXPECT_TRUE(fs::exists(dir / ".stages" / "noop.done"));
  fs::remove_all(dir);
}

// The tasks of a study: one per key (the first one's stands), dependencies below 0 ignored.
TEST(RankTasks, OneTaskPerKeyAndNoDependencyOnNothing) {
  RankTasks g;
  int calls = 0;
  const int a = g.add("k/a", "a", 5, {-1}, [&] { ++calls; });
  const int b = g.add("k/b", "b", 1, {a, -1}, [&] { calls += 10; });
  EXPECT_EQ(g.add("k/a", "another a", 9, {b}, [] {}), a);
  ASSERT_EQ(g.tasks().size(), 2u);
  EXPECT_TRUE(g.tasks()[size_t(a)].after.empty());
  EXPECT_EQ(g.tasks()[size_t(b)].after, std::vector<int>{a});
  EXPECT_EQ(g.tasks()[size_t(a)].label, "a");
  g.tasks()[size_t(a)].run();
  EXPECT_EQ(calls, 1);
  EXPECT_GE(threads_per_rank(), 1);
}
