// The program end to end: synth -> train-all -> eval, and its behaviour on bad input and on
// interruption (exit status, messages naming the file, no partial or destroyed outputs).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/model.hpp"

#include "tests/common/csv_rows.hpp"
#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;

using Result = yarnhom::test::CliResult;

namespace {

Result run(const std::string& args) { return yarnhom::test::run_cli(args); }

struct Dir {
  fs::path dir;
  Dir() {
    dir = fs::temp_directory_path() /
          ("yarnhom_cli_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir);
  }
  ~Dir() { fs::remove_all(dir); }
  std::string operator/(const std::string& f) const { return (dir / f).string(); }
};

std::vector<std::vector<double>> parse_csv(const std::string& text, std::string* header) {
  return yarnhom::test::parse_csv_rows(text, header);
}

}  // namespace

TEST(Cli, SynthTrainEvalEndToEnd) {
  Dir d;
  auto r = run("synth -o " + d / "d.h5");
  ASSERT_EQ(r.status, 0) << r.out;
  r = run("train-all " + d / "d.h5" + " -o " + d / "m.h5" + " --epochs 3 --terms 0,02 -q");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("term"), std::string::npos);
  EXPECT_NE(r.out.find("02"), std::string::npos);
  auto m = yarnhom::read_model(d / "m.h5");
  ASSERT_EQ(m.networks.size(), 2u);
  EXPECT_EQ(m.networks[1].history.size(), 3u);

  // eval's derivative columns agree with finite differences of its own energy column, so the
  // physical-unit scaling is right.
  const double a = 0.3, b = 0.2, h = 1e-4;
  std::ostringstream at;
  at << " --at " << a << "," << b << " --at " << a + h << "," << b << " --at " << a - h << "," << b
     << " --at " << a << "," << b + h << " --at " << a << "," << b - h;
  r = run("eval " + d / "m.h5" + " --term 02" + at.str());
  ASSERT_EQ(r.status, 0) << r.out;
  std::string header;
  auto rows = parse_csv(r.out, &header);
  EXPECT_EQ(header.rfind("s_x,s_y,psi,d/ds_x,d/ds_y,d2/ds_x/ds_x", 0), 0u) << header;
  ASSERT_EQ(rows.size(), 5u);
  ASSERT_EQ(rows[0].size(), 12u);  // 2 strains + 10 jet channels
  EXPECT_NEAR(rows[0][3], (rows[1][2] - rows[2][2]) / (2 * h), 1e-5 * (1 + std::abs(rows[0][3])));
  EXPECT_NEAR(rows[0][4], (rows[3][2] - rows[4][2]) / (2 * h), 1e-5 * (1 + std::abs(rows[0][4])));
}

TEST(Cli, BadDatasetIsRefusedNamingTheFileAndKeepsTheOldModel) {
  Dir d;
  ASSERT_EQ(run("synth -o " + d / "d.h5").status, 0);
  ASSERT_EQ(run("train-all " + d / "d.h5" + " -o " + d / "m.h5" + " --epochs 2 --terms 0 -q").status, 0);
  const auto size = fs::file_size(d / "m.h5");
  std::ofstream(d / "bad.h5") << "not hdf5";
  auto r = run("train-all " + d / "bad.h5" + " -o " + d / "m.h5" + " --epochs 2");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find(d / "bad.h5"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not an HDF5 file"), std::string::npos) << r.out;
  EXPECT_EQ(fs::file_size(d / "m.h5"), size);

  r = run("train-all " + d / "d.h5" + " -o " + d / "m.h5" + " --terms 04");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("unknown term '04'"), std::string::npos) << r.out;
  r = run("eval " + d / "m.h5" + " --term 0 --at 0.1,0.2");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("needs 1 value"), std::string::npos) << r.out;
}

TEST(Cli, InterruptedTrainingLeavesNoPartialFileAndKeepsTheOldModel) {
  Dir d;
  ASSERT_EQ(run("synth --preset paper -o " + d / "d.h5").status, 0);
  std::ofstream(d / "m.h5") << "previous model";
  const pid_t pid = fork();
  if (pid == 0) {
    execl(YARNHOM_BINARY, YARNHOM_BINARY, "train-all", (d / "d.h5").c_str(), "-o",
          (d / "m.h5").c_str(), "--epochs", "100000", "-q", (char*)nullptr);
    _exit(127);
  }
  usleep(700 * 1000);
  kill(pid, SIGINT);
  int st;
  waitpid(pid, &st, 0);
  std::ifstream in(d / "m.h5");
  std::string content((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(content, "previous model");
  for (auto& e : fs::directory_iterator(d.dir))
    EXPECT_EQ(e.path().string().find(".partial"), std::string::npos) << e.path();
}

TEST(Cli, HelpExplainsEveryOption) {
  auto r = run("train-all --help");
  EXPECT_EQ(r.status, 0);
  for (const char* opt : {"--backend", "--epochs", "--seed", "--threads", "--terms", "--w-c", "--stencil-c"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
}
