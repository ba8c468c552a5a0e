// Issue 11, items 2-5: outputs never clobber what they must not, are checked before any work,
// stale temporaries are cleaned, and a killed pipeline takes its stages with it. Through the
// program itself.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "core/atomic_file.hpp"
#include "core/dataset.hpp"
#include "tests/common/run_cli.hpp"
#include "tests/common/process_tree.hpp"
#include "tests/common/small_files.hpp"

namespace fs = std::filesystem;
using yarnhom::test::run_cli;
using yarnhom::test::TempDir;

namespace {

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool is_fifo(const std::string& p) {
  struct stat st;
  return ::lstat(p.c_str(), &st) == 0 && S_ISFIFO(st.st_mode);
}

}  // namespace

// synth -o X where X is a FIFO, a socket, a character device (when we may make one), a
// folder: refused, naming X and -o, and X is left as it was.
TEST(Outputs, SpecialFilesAndFoldersAreNeverReplaced) {
  TempDir d("out");
  const std::string fifo = d / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  auto r = run_cli("synth -o " + fifo);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find(fifo), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("FIFO"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("-o"), std::string::npos) << r.out;
  EXPECT_TRUE(is_fifo(fifo));

  const std::string sock = d / "sock";
  const int s = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", sock.c_str());
  if (sock.size() < sizeof addr.sun_path && ::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) {
    r = run_cli("synth -o " + sock);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.out.find("socket"), std::string::npos) << r.out;
    struct stat st;
    EXPECT_TRUE(::lstat(sock.c_str(), &st) == 0 && S_ISSOCK(st.st_mode));
  }
  ::close(s);

  // A device node of our own (the null device's numbers), only where we may make one.
  const std::string dev = d / "dev";
  if (::mknod(dev.c_str(), S_IFCHR | 0600, makedev(1, 3)) == 0) {
    r = run_cli("synth -o " + dev);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.out.find("character device"), std::string::npos) << r.out;
    struct stat st;
    EXPECT_TRUE(::lstat(dev.c_str(), &st) == 0 && S_ISCHR(st.st_mode));
  }

  fs::create_directories(d / "folder");
  r = run_cli("synth -o " + d / "folder");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("is a directory"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::is_directory(d / "folder"));
  EXPECT_TRUE(fs::is_empty(d / "folder"));
}

// A symbolic link is followed: the file it points to is written, the link stays a link. A link
// to a missing file is refused.
TEST(Outputs, SymbolicLinksAreFollowedDeliberately) {
  TempDir d("out");
  std::ofstream(d / "target.h5") << "old";
  fs::create_symlink(d / "target.h5", d / "link.h5");
  auto r = run_cli("synth -o " + d / "link.h5");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(fs::is_symlink(d / "link.h5"));
  EXPECT_NO_THROW(yarnhom::read_dataset(d / "target.h5"));
  for (auto& e : fs::directory_iterator(d.dir))
    EXPECT_EQ(e.path().string().find(".partial"), std::string::npos) << e.path();

  fs::create_symlink(d / "missing.h5", d / "dangling.h5");
  r = run_cli("synth -o " + d / "dangling.h5");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("symbolic link to a missing file"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(d / "missing.h5"));
}

// train-all D -o D, bake M -o M, and the same through a hard link or a symbolic link: refused
// before any work, the input unchanged.
TEST(Outputs, AnInputIsNeverItsOwnOutput) {
  TempDir d("out");
  const auto f = yarnhom::test::write_small_files(d);
  const std::string ds_bytes = slurp(f.dataset), model_bytes = slurp(f.model);
  fs::create_hard_link(f.dataset, d / "hard.h5");
  fs::create_symlink(f.model, d / "soft.h5");
  struct Case {
    std::string args, input;
  };
  for (const Case& c : {Case{"train-all " + f.dataset + " -o " + f.dataset + " --epochs 1 -q", f.dataset},
                        Case{"train-all " + f.dataset + " -o " + d / "hard.h5" + " --epochs 1 -q", f.dataset},
                        Case{"bake " + f.model + " -o " + f.model, f.model},
                        Case{"bake " + f.model + " -o " + d / "soft.h5", f.model},
                        // The dataset the model names is an input of bake too.
                        Case{"bake " + f.model + " -o " + f.dataset, f.dataset},
                        Case{"error " + f.model + " --csv " + f.dataset, f.dataset}}) {
    const auto t0 = std::chrono::steady_clock::now();
    auto r = run_cli(c.args);
    EXPECT_NE(r.status, 0) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find("writing it would destroy it"), std::string::npos) << c.args << "\n" << r.out;
    EXPECT_LT(seconds_since(t0), 5.0) << c.args;
  }
  EXPECT_EQ(slurp(f.dataset), ds_bytes);
  EXPECT_EQ(slurp(f.model), model_bytes);
  EXPECT_TRUE(fs::is_symlink(d / "soft.h5"));
}

// -o naming a folder or a path in a missing folder is refused at once, not after the work
// (train-all with 100000 epochs would run for minutes).
TEST(Outputs, BadOutputPathsAreRefusedBeforeAnyWork) {
  TempDir d("out");
  const auto f = yarnhom::test::write_small_files(d);
  for (const std::string& out : {d.dir.string(), d / "no/such/folder/m.h5", d / "m.h5/"}) {
    const auto t0 = std::chrono::steady_clock::now();
    auto r = run_cli("train-all " + f.dataset + " -o " + out + " --epochs 100000 -q");
    EXPECT_NE(r.status, 0) << out << "\n" << r.out;
    EXPECT_NE(r.out.find("(-o)"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("cannot move the finished file"), std::string::npos) << r.out;
    EXPECT_LT(seconds_since(t0), 5.0) << out;
  }
  // produce: the same before the rest relaxation; rve: each of its outputs.
  auto r = run_cli("produce stockinette -o " + d / "none/ds.h5 --terms 0");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("does not exist"), std::string::npos) << r.out;
  r = run_cli("rve stockinette --obj " + d.dir.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("(--obj)"), std::string::npos) << r.out;
  r = run_cli("rve stockinette --out " + d / "s.h5" + " --obj " + d / "s.h5");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("name the same file"), std::string::npos) << r.out;
}

// A run killed during its final write leaves OUTPUT.partial-<pid>; the next run writing the
// same output removes those of dead processes, says so, and leaves a live writer's alone.
TEST(Outputs, StaleTemporariesAreRemovedWithALine) {
  TempDir d("out");
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);  // a pid that no longer runs
  const std::string stale = yarnhom::AtomicOutput::temporary_name(d / "d.h5", child);
  const std::string live = yarnhom::AtomicOutput::temporary_name(d / "d.h5", ::getpid());
  const std::string other = yarnhom::AtomicOutput::temporary_name(d / "other.h5", child);
  std::ofstream(stale) << "half a file";
  std::ofstream(live) << "being written";
  std::ofstream(other) << "another output's";
  auto r = run_cli("synth -o " + d / "d.h5");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_NE(r.out.find("removed " + stale), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(other));
}

namespace {

using yarnhom::test::alive;
using yarnhom::test::children_of;

}  // namespace

// Killing pipeline (SIGKILL: no cleanup of its own can run) kills the stage it was running.
TEST(Outputs, KilledPipelineTakesItsStagesWithIt) {
  if (!fs::exists("/proc/self/task")) GTEST_SKIP() << "needs Linux /proc";
  TempDir d("out");
  const std::string run = d / "run";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);  // our own group, so that nothing here reaches the test runner
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execl(YARNHOM_BINARY, YARNHOM_BINARY, "pipeline", "synthetic", "-o", run.c_str(), "--epochs", "1000000",
            "--threads", "1", (char*)nullptr);
    ::_exit(127);
  }
  // Wait for the train-all stage (synth takes a fraction of a second).
  std::vector<pid_t> stage;
  const auto t0 = std::chrono::steady_clock::now();
  while (seconds_since(t0) < 60) {
    std::vector<pid_t> all, frontier = children_of(pid);
    while (!frontier.empty()) {
      const pid_t c = frontier.back();
      frontier.pop_back();
      all.push_back(c);
      for (pid_t g : children_of(c)) frontier.push_back(g);
    }
    bool training = false;
    for (pid_t c : all) {
      std::ifstream in("/proc/" + std::to_string(c) + "/cmdline");
      std::string cmd((std::istreambuf_iterator<char>(in)), {});
      training = training || cmd.find("train-all") != std::string::npos;
    }
    if (training) {
      stage = all;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_FALSE(stage.empty()) << "the train-all stage never started";
  ::kill(pid, SIGKILL);
  ::waitpid(pid, nullptr, 0);
  const auto t1 = std::chrono::steady_clock::now();
  bool any = true;
  while (any && seconds_since(t1) < 5) {
    any = false;
    for (pid_t c : stage) any = any || alive(c);
    if (any) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (pid_t c : stage) {
    EXPECT_FALSE(alive(c)) << "stage process " << c << " outlived the killed pipeline";
    if (alive(c)) ::kill(c, SIGKILL);
  }
}
