// Issue 32 ("hardening, second round"): inputs that are FIFOs are refused before they are
// opened (sim's scene file, --material, and a scene's "material" and "mesh": {"obj"}); NaN,
// infinite and negative floating options of sim and export-hylc are refused at parse time
// naming the option and the value; export-hylc's -o may not be its input (the same path or a
// symbolic link to it), and a failed export leaves the previous output as it was.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/common/run_cli.hpp"
#include "tests/common/small_files.hpp"

namespace fs = std::filesystem;
using yarnhom::test::run_cli_limited;

namespace {

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

const char* kRectangle = R"("mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 2, "ny": 2}})";

// A baked file with an areal density (export-hylc's and sim's material).
std::string small_baked(const yarnhom::test::TempDir& d) {
  const auto f = yarnhom::test::write_small_files(d);
  return f.baked;
}

// Refused: an error status (1, or CLI11's 105 for a bad option), not a signal or the time limit.
bool refused(int status) { return status != 0 && status < 128; }

// Runs args under a 20 s limit: refused within 10 s, naming `named` and `words`.
void expect_refused_quickly(const std::string& args, const std::string& named, const std::string& words) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = run_cli_limited(args, 20);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(refused(r.status)) << r.status << " " << args << "\n" << r.out;
  EXPECT_LT(s, 10.0) << args;
  EXPECT_NE(r.out.find(named), std::string::npos) << args << ": does not name " << named << "\n" << r.out;
  EXPECT_NE(r.out.find(words), std::string::npos) << args << ": does not say '" << words << "'\n" << r.out;
}

}  // namespace

TEST(Hardening2, FifoInputsOfSimAreRefusedBeforeTheyAreOpened) {
  yarnhom::test::TempDir d("fifo_sim");
  const std::string fifo = d / "fifo.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const std::string fifo_obj = d / "fifo.obj";
  ASSERT_EQ(::mkfifo(fifo_obj.c_str(), 0644), 0);
  const std::string baked = small_baked(d);
  // The scene file itself.
  expect_refused_quickly("sim " + fifo + " -o " + d / "o1 -q --material " + baked, fifo, "FIFO");
  // --material.
  expect_refused_quickly("sim drape -o " + d / "o2 -q --material " + fifo, fifo, "FIFO");
  // The scene's "material".
  std::ofstream(d / "scene_mat.json") << "{" << kRectangle << R"(, "material": "fifo.json"})";
  expect_refused_quickly("sim " + d / "scene_mat.json -o " + d / "o3 -q", fifo, "FIFO");
  // The scene's "mesh": {"obj": ...}.
  std::ofstream(d / "scene_obj.json") << R"({"mesh": {"obj": "fifo.obj"}})";
  expect_refused_quickly("sim " + d / "scene_obj.json -o " + d / "o4 -q --material " + baked, fifo_obj, "FIFO");
  for (const char* o : {"o1", "o2", "o3", "o4"}) EXPECT_FALSE(fs::exists(d / o)) << o;
}

TEST(Hardening2, NonFiniteAndNegativeFloatingOptionsAreRefusedNamingOptionAndValue) {
  yarnhom::test::TempDir d("nan_opts");
  const std::string baked = small_baked(d);
  // sim: each option with nan, inf and (where invalid) a negative value and zero.
  struct Case {
    const char* option;
    bool zero_ok;
  };
  for (const Case& c : {Case{"--dt", false}, Case{"--density", false}, Case{"--tol", false},
                        Case{"--rayleigh-alpha", true}, Case{"--rayleigh-beta", true}, Case{"--air", true},
                        Case{"--friction", true}, Case{"--friction-eps-v", false}}) {
    std::vector<std::string> bad = {"nan", "inf", "-inf", "-1"};
    if (!c.zero_ok) bad.push_back("0");
    for (const std::string& v : bad) {
      const auto r = run_cli_limited("sim drape -o " + d / "o -q --frames 1 --render none --material " + baked + " " +
                                         c.option + " " + v,
                                     30);
      EXPECT_TRUE(refused(r.status)) << r.status << " " << c.option << " " << v << "\n" << r.out;
      EXPECT_NE(r.out.find(c.option), std::string::npos) << c.option << " " << v << "\n" << r.out;
      EXPECT_NE(r.out.find("'" + v + "'"), std::string::npos) << c.option << " " << v << "\n" << r.out;
    }
  }
  EXPECT_FALSE(fs::exists(d / "o"));
  // export-hylc --density and --margin.
  for (const std::string& v : {"nan", "inf", "-1", "0"}) {
    const auto r = run_cli_limited("export-hylc " + baked + " -o " + d / "m.json --density " + v, 30);
    EXPECT_TRUE(refused(r.status)) << r.status << " --density " << v << "\n" << r.out;
    EXPECT_NE(r.out.find("--density"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("'" + v + "'"), std::string::npos) << r.out;
  }
  for (const std::string& v : {"nan", "inf", "-inf", "-1", "1e-300", "5e-7", "11"}) {
    const auto r = run_cli_limited("export-hylc " + baked + " -o " + d / "m.json --density 0.3 --margin " + v, 30);
    EXPECT_TRUE(refused(r.status)) << r.status << " --margin " << v << "\n" << r.out;
    EXPECT_NE(r.out.find("--margin"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("'" + v + "'"), std::string::npos) << r.out;
  }
  EXPECT_FALSE(fs::exists(d / "m.json"));
  // The smallest margin allowed writes knots sim accepts; 0 writes the box's own.
  for (const std::string& v : {"1e-6", "0"}) {
    const std::string out = d / ("m" + v + ".json");
    auto r = run_cli_limited("export-hylc " + baked + " -o " + out + " --density 0.3 --margin " + v, 30);
    ASSERT_EQ(r.status, 0) << "--margin " << v << "\n" << r.out;
    r = run_cli_limited("sim drape -o " + d / ("s" + v) + " -q --frames 1 --resolution 2 --render none --no-frames --material " + out, 120);
    EXPECT_EQ(r.status, 0) << "--margin " << v << "\n" << r.out;
  }
}

TEST(Hardening2, ExportHylcRefusesToReplaceItsInputAndKeepsThePreviousOutput) {
  yarnhom::test::TempDir d("export_self");
  const std::string baked = small_baked(d);
  const std::string before = slurp(baked);
  // The same path.
  auto r = run_cli_limited("export-hylc " + baked + " -o " + baked + " --density 0.3", 30);
  EXPECT_TRUE(refused(r.status)) << r.status << " " << r.out;
  EXPECT_NE(r.out.find(baked), std::string::npos) << r.out;
  EXPECT_EQ(slurp(baked), before);
  // A symbolic link to it.
  const std::string link = d / "link.json";
  fs::create_symlink(baked, link);
  r = run_cli_limited("export-hylc " + baked + " -o " + link + " --density 0.3", 30);
  EXPECT_TRUE(refused(r.status)) << r.status << " " << r.out;
  EXPECT_NE(r.out.find(link), std::string::npos) << r.out;
  EXPECT_EQ(slurp(baked), before);
  EXPECT_TRUE(fs::is_symlink(link));
  // A hard link to it.
  const std::string hard = d / "hard.json";
  fs::create_hard_link(baked, hard);
  r = run_cli_limited("export-hylc " + baked + " -o " + hard + " --density 0.3", 30);
  EXPECT_TRUE(refused(r.status)) << r.status << " " << r.out;
  EXPECT_EQ(slurp(baked), before);
  // A failed export (the input is not a baked file) leaves the previous output as it was.
  const std::string out = d / "m.json";
  ASSERT_EQ(run_cli_limited("export-hylc " + baked + " -o " + out + " --density 0.3", 30).status, 0);
  const std::string previous = slurp(out);
  std::ofstream(d / "junk.h5") << "not hdf5";
  r = run_cli_limited("export-hylc " + d / "junk.h5" + " -o " + out + " --density 0.3", 30);
  EXPECT_TRUE(refused(r.status)) << r.status << " " << r.out;
  EXPECT_EQ(slurp(out), previous);
  for (const auto& e : fs::directory_iterator(d.dir))
    EXPECT_EQ(e.path().string().find(".partial-"), std::string::npos) << e.path();
}
