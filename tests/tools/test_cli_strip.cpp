// yarnhom strip end to end: outputs, a run killed after its first load step and rerun gives
// the same force curve as an uninterrupted one, a longer --stretch extends a finished run,
// other settings are refused, bad options are named.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

struct Dir {
  fs::path dir;
  Dir() {
    dir = fs::temp_directory_path() / ("yarnhom_cli_strip_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir);
  }
  ~Dir() { fs::remove_all(dir); }
  std::string operator/(const std::string& f) const { return (dir / f).string(); }
};

std::string pattern() {
  const fs::path p = fs::path(YARNHOM_SOURCE_DIR) / ".." / "shared" / "patterns" / "stocktiny.pyp";
  return fs::exists(p) ? p.string() : std::string();
}

// A stocktiny wale strip three courses high whose top and bottom courses are clamped: small
// and quick (the tiny patterns' straight rest yarn lets unclamped edge courses pull out).
std::string args(const std::string& clamp = "0.0009") {
  return " --direction wale --size 0.0035,0.0027 --clamp " + clamp + " --no-plots --threads 1";
}

// force.csv without its timing columns (those whose header ends in "seconds").
std::vector<std::string> curve(const std::string& csv_path) {
  std::ifstream in(csv_path);
  std::string line;
  std::vector<std::string> rows;
  std::vector<bool> timing;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::string cell, kept;
    for (size_t c = 0; std::getline(ls, cell, ','); ++c) {
      if (rows.empty()) timing.push_back(cell.size() >= 7 && cell.compare(cell.size() - 7, 7, "seconds") == 0);
      if (c >= timing.size() || !timing[c]) kept += cell + ",";
    }
    rows.push_back(kept);
  }
  return rows;
}

}  // namespace

TEST(CliStrip, KilledAndRerunGivesTheSameForceCurve) {
  if (pattern().empty()) GTEST_SKIP() << "shared patterns not found";
  Dir d;
  auto r = yarnhom::test::run_cli("strip " + pattern() + args() + " --stretch 1.0:1.1:0.05 -o " + d / "whole");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("ETA"), std::string::npos) << "progress line";
  for (const char* f : {"force.csv", "strip.obj", "settings.txt", "steps/step_002.h5", "centrelines/step_002.obj"})
    EXPECT_TRUE(fs::exists(d / ("whole/" + std::string(f)))) << f;
  const auto whole = curve(d / "whole/force.csv");
  ASSERT_EQ(whole.size(), 4u);  // header + 3 steps

  // Kill it (SIGKILL: no chance to clean up) once its first load step is on disk.
  const std::string out = d / "killed";
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string p = pattern();
    execl(YARNHOM_BINARY, YARNHOM_BINARY, "strip", p.c_str(), "--direction", "wale", "--size", "0.0035,0.0027",
          "--clamp", "0.0009", "--no-plots", "--threads", "1", "--stretch", "1.0:1.1:0.05", "-o", out.c_str(),
          (char*)nullptr);
    _exit(127);
  }
  const auto t0 = std::chrono::steady_clock::now();
  while (!fs::exists(out + "/steps/step_000.h5") && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(pid, SIGKILL);
  int st;
  waitpid(pid, &st, 0);
  r = yarnhom::test::run_cli("strip " + pattern() + args() + " --stretch 1.0:1.1:0.05 -o " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("kept from"), std::string::npos) << r.out;
  EXPECT_EQ(curve(out + "/force.csv"), whole);
  for (auto& e : fs::recursive_directory_iterator(out))
    EXPECT_EQ(e.path().string().find(".partial"), std::string::npos) << e.path();
  // Killed after its last step file but before force.csv: a rerun keeps every step and writes
  // the whole table.
  fs::remove(out + "/force.csv");
  r = yarnhom::test::run_cli("strip " + pattern() + args() + " --stretch 1.0:1.1:0.05 -o " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(curve(out + "/force.csv"), whole);

  // A longer list extends the finished run; its first steps are kept.
  r = yarnhom::test::run_cli("strip " + pattern() + args() + " --stretch 1.0:1.15:0.05 -o " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto longer = curve(out + "/force.csv");
  ASSERT_EQ(longer.size(), 5u);
  for (size_t k = 0; k < whole.size(); ++k) EXPECT_EQ(longer[k], whole[k]);

  // A shorter list (issue 32): the later steps' files of the longer run are removed, saying so,
  // so that the folder holds what force.csv lists.
  r = yarnhom::test::run_cli("strip " + pattern() + args() + " --stretch 1.0:1.05:0.05 -o " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(curve(out + "/force.csv").size(), 3u);
  EXPECT_TRUE(fs::exists(out + "/centrelines/step_001.obj"));
  for (const char* f : {"/steps/step_002.h5", "/steps/step_003.h5", "/centrelines/step_002.obj", "/centrelines/step_003.obj"})
    EXPECT_FALSE(fs::exists(out + f)) << f;
  EXPECT_NE(r.out.find("removed 2 load step(s) of an earlier run"), std::string::npos) << r.out;

  // Other settings in the same folder are refused, naming what differs.
  r = yarnhom::test::run_cli("strip " + pattern() + args("0.001") + " --stretch 1.0:1.1:0.05 -o " + out);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("other settings"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("clamp"), std::string::npos) << r.out;
}

TEST(CliStrip, BadOptionsAreNamed) {
  Dir d;
  auto r = yarnhom::test::run_cli("strip plain --direction diagonal -o " + d / "x");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--direction"), std::string::npos) << r.out;
  r = yarnhom::test::run_cli("strip plain --stretch 1.7:1.0:0.05 -o " + d / "x");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--stretch"), std::string::npos) << r.out;
  r = yarnhom::test::run_cli("strip plain --size 0.05 -o " + d / "x");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--size"), std::string::npos) << r.out;
  r = yarnhom::test::run_cli("strip plain --clamp 0.06 -o " + d / "x");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--clamp"), std::string::npos) << r.out;
  // Validated like every command (tools/cli/cli_util.hpp): non-finite numbers, an output that is
  // not a folder, a pattern that is not a regular file, all refused before any work.
  r = yarnhom::test::run_cli("strip plain --clamp nan -o " + d / "x");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--clamp"), std::string::npos) << r.out;
  r = yarnhom::test::run_cli("strip plain --tolerance inf -o " + d / "x");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--tolerance"), std::string::npos) << r.out;
  r = yarnhom::test::run_cli("strip plain --size 0.05,nan -o " + d / "x");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--size"), std::string::npos) << r.out;
  {
    std::ofstream(d / "file") << "not a folder";
    r = yarnhom::test::run_cli("strip plain -o " + d / "file");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.out.find("file"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("-o"), std::string::npos) << r.out;
    fs::create_directories(d / "folder.pyp");
    r = yarnhom::test::run_cli("strip " + d / "folder.pyp" + " -o " + d / "y");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.out.find("folder.pyp"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(d / "y")) << "nothing written for a refused input";
  }
  r = yarnhom::test::run_cli("strip no_such_pattern -o " + d / "x");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("no_such_pattern"), std::string::npos) << r.out;
  r = yarnhom::test::run_cli("strip --help");
  EXPECT_EQ(r.status, 0);
  for (const char* opt : {"--size", "--direction", "--stretch", "--clamp", "--connector-scale", "--material", "--restart"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
}
