// Issue 32 items 5, 8 and 9: clean one-line refusals instead of library texts (std::bad_alloc for
// huge scene rectangles and strips, the JSON library's text for a number that overflows a
// double, "filesystem error" for -o naming a file, a FIFO, /dev/null or /proc/...), and a sim
// rerun into a folder of an earlier run removes what that run wrote and this one does not.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <iterator>

#include "tests/common/run_cli.hpp"
#include "tests/common/small_files.hpp"

namespace fs = std::filesystem;
using yarnhom::test::run_cli_limited;

namespace {

bool refused(int status) { return status != 0 && status < 128; }

// Refused within 5 s, in one line "yarnhom: error: ..." naming each of `words`, without a
// library's text.
void expect_clean_refusal(const std::string& args, const std::vector<std::string>& words) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = run_cli_limited(args, 30);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(refused(r.status)) << r.status << " " << args << "\n" << r.out;
  EXPECT_LT(s, 5.0) << args;
  for (const std::string& w : words) EXPECT_NE(r.out.find(w), std::string::npos) << args << ": no '" << w << "'\n" << r.out;
  for (const char* lib : {"bad_alloc", "filesystem error", "json.exception", "basic_filebuf", "what()"})
    EXPECT_EQ(r.out.find(lib), std::string::npos) << args << ": library text '" << lib << "'\n" << r.out;
  EXPECT_EQ(r.out.find("yarnhom: error: "), r.out.rfind("yarnhom: error: ")) << args << ": more than one error\n" << r.out;
}

std::string pattern_file() {
  const fs::path p = fs::path(YARNHOM_SOURCE_DIR) / ".." / "shared" / "patterns" / "stocktiny.pyp";
  return fs::exists(p) ? p.string() : "plain";  // the built-in plain weave: tiny, straight at rest
}

}  // namespace

TEST(Hardening3, HugeSizesAndOverflowingNumbersAreRefusedWithTheRuleNamingFileAndKey) {
  yarnhom::test::TempDir d("h3_sizes");
  const std::string baked = yarnhom::test::write_small_files(d).baked;
  std::ofstream(d / "big.json") << R"({"mesh": {"rectangle": {"width": 1, "height": 1, "nx": 100000000, "ny": 100000000}}})";
  expect_clean_refusal("sim " + d / "big.json -o " + d / "o -q --material " + baked,
                       {d / "big.json", "mesh.rectangle", "at most 4000000"});
  std::ofstream(d / "inf.json") << R"({"mesh": {"rectangle": {"width": 1e999, "height": 1, "nx": 2, "ny": 2}}})";
  expect_clean_refusal("sim " + d / "inf.json -o " + d / "o -q --material " + baked,
                       {d / "inf.json", "mesh.rectangle.width", "1e999", "finite"});
  std::ofstream(d / "inf2.json") << R"({"mesh": {"rectangle": {"width": 1, "height": 1, "nx": 2, "ny": 2}},)"
                                 << R"( "colliders": [{"plane": {"point": [0, 0, 0]}}, {"sphere": {"center": [0, 0, -1e999], "radius": 1}}]})";
  expect_clean_refusal("sim " + d / "inf2.json -o " + d / "o -q --material " + baked,
                       {d / "inf2.json", "colliders[1].sphere.center[2]"});
  std::ofstream(d / "deep.json") << std::string(100000, '[') << std::string(100000, ']');
  expect_clean_refusal("sim " + d / "deep.json -o " + d / "o -q --material " + baked, {d / "deep.json", "nested deeper"});
  fs::create_directories(d / "folder.json");
  expect_clean_refusal("sim " + d / "folder.json -o " + d / "o -q --material " + baked, {d / "folder.json", "directory"});
  expect_clean_refusal("sim stretch --size 1e9,1e9 -o " + d / "o -q --material " + baked, {"--size", "at most 4e6"});
  expect_clean_refusal("strip " + pattern_file() + " --size 1e9,1e9 --no-plots -o " + d / "o",
                       {"--size", "yarn vertices", "at most 1000000"});
  EXPECT_FALSE(fs::exists(d / "o"));
}

TEST(Hardening3, OutputFoldersThatAreFilesOrCannotBeMadeAreRefusedInOneLine) {
  yarnhom::test::TempDir d("h3_outputs");
  const auto f = yarnhom::test::write_small_files(d);
  std::ofstream(d / "file") << "x";
  ASSERT_EQ(::mkfifo((d / "fifo").c_str(), 0644), 0);
  std::vector<std::pair<std::string, std::string>> outs = {
      {d / "file", "regular file"}, {d / "fifo", "FIFO"}, {"/dev/null", "character device"}, {d / "file/sub", "not a folder"}};
  if (fs::is_directory("/proc/self")) outs.push_back({"/proc/yarnhom-no-such/out", "cannot create"});
  const std::string pat = d / "curved.pyp";  // passes strip's checks: -o is what is refused
  yarnhom::test::write_curved_pattern(pat);
  for (const auto& [out, why] : outs) {
    for (const std::string& cmd :
         {"sim hang -q --frames 1 --material " + f.baked + " -o " + out, "strip " + pat + " --no-plots -o " + out,
          "accuracy " + pat + " --direction course -o " + out, "study table5 " + pat + " -o " + out,
          "study strip-width " + pat + " -o " + out, "study rve-size " + pat + " -o " + out,
          "study architectures " + f.dataset + " --no-plot -o " + out, "pipeline " + pat + " -o " + out})
      expect_clean_refusal(cmd, {out, why, "(-o)"});
  }
  EXPECT_EQ(std::ifstream(d / "file").get(), 'x');
}

TEST(Hardening3, SimRerunRemovesWhatTheEarlierRunWroteAndThisOneDoesNot) {
  yarnhom::test::TempDir d("h3_rerun");
  const std::string baked = yarnhom::test::write_small_files(d).baked;
  const std::string out = d / "run", base = "sim hang -q --resolution 3 --render none --density 0.3 --material " + baked + " -o " + out;
  auto r = run_cli_limited(base + " --frames 6", 60);
  ASSERT_EQ(r.status, 0) << r.out;
  ASSERT_TRUE(fs::exists(out + "/frames/frame_0006.obj"));
  // A killed run's temporary and a file of the user's.
  std::ofstream(out + "/frames/frame_0003.obj.partial-999999999") << "half";
  std::ofstream(out + "/notes.txt") << "mine";
  r = run_cli_limited(base + " --frames 2", 60);
  ASSERT_EQ(r.status, 0) << r.out;
  for (int k = 0; k <= 2; ++k) EXPECT_TRUE(fs::exists(out + "/frames/frame_000" + std::to_string(k) + ".obj")) << k;
  for (int k = 3; k <= 6; ++k) EXPECT_FALSE(fs::exists(out + "/frames/frame_000" + std::to_string(k) + ".obj")) << k;
  EXPECT_FALSE(fs::exists(out + "/frames/frame_0003.obj.partial-999999999"));
  EXPECT_TRUE(fs::exists(out + "/notes.txt"));
  EXPECT_NE(r.out.find("earlier run"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("4 beyond this run's 2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frame_0003.obj.partial-999999999"), std::string::npos) << r.out;
  // --no-frames: no frame of the earlier run is left to be taken for this one's.
  r = run_cli_limited(base + " --frames 2 --no-frames", 60);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_FALSE(fs::exists(out + "/frames/frame_0000.obj"));
}

// Issue 32 item 8: a train-all that fails (a network's loss became non-finite: exit 2) leaves
// the previous model as it was; the networks that trained go to STEM.failed.h5 beside it.
TEST(Hardening3, FailedTrainAllLeavesThePreviousModelAsItWas) {
  yarnhom::test::TempDir d("h3_train");
  const std::string ds = d / "synth.h5", out = d / "model.h5";
  ASSERT_EQ(run_cli_limited("synth --preset quick -o " + ds, 60).status, 0);
  auto r = run_cli_limited("train-all " + ds + " -o " + out + " -q --epochs 2 --terms 0,02 --threads 2", 60);
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(out, std::ios::binary);
  const std::string before((std::istreambuf_iterator<char>(in)), {});
  // --lr 1e12 for 5 epochs: 2 of the 14 networks end non-finite, the others train.
  r = run_cli_limited("train-all " + ds + " -o " + out + " -q --epochs 5 --polish 0 --lr 1e12 --threads 2", 60);
  EXPECT_EQ(r.status, 2) << r.out;
  std::ifstream again(out, std::ios::binary);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(again)), {}), before) << "the previous model was replaced";
  EXPECT_NE(r.out.find("left as it was"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(d / "model.failed.h5")) << r.out;
  for (const auto& e : fs::directory_iterator(d.dir))
    EXPECT_EQ(e.path().string().find(".partial-"), std::string::npos) << e.path();
  // Every network failing: nothing written, the previous model kept.
  r = run_cli_limited("train-all " + ds + " -o " + out + " -q --epochs 5 --polish 0 --lr 1e30 --terms 0 --threads 2", 60);
  EXPECT_EQ(r.status, 2) << r.out;
  std::ifstream third(out, std::ios::binary);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(third)), {}), before);
}

// Issue 32 item 6: accuracy and the studies check their own options and those they pass to
// their stages (strip, sim stretch) before the first stage starts: refused in well under a
// second, naming the option and its value, nothing made.
TEST(Hardening3, AccuracyAndStudiesRefuseBadOptionsBeforeTheFirstStage) {
  yarnhom::test::TempDir d("h3_late");
  const auto f = yarnhom::test::write_small_files(d);
  const std::string pat = d / "curved.pyp", out = d / "acc";  // a pattern strip takes at any size
  yarnhom::test::write_curved_pattern(pat);
  const std::string acc = "accuracy " + pat + " --direction course -o " + out + " ";
  struct Case {
    std::string args;
    std::vector<std::string> words;
  };
  const std::vector<Case> cases = {
      {acc + "--size 0,0.1", {"--size", "0,0.1"}},
      {acc + "--size 1e9,1e9", {"--size", "at most"}},
      {acc + "--stretch 1.0:0.5:0.1", {"--stretch", "1.0:0.5:0.1"}},
      {acc + "--stretch 1.2:1.5:0.1", {"--stretch", "1.2:1.5:0.1"}},
      {acc + "--stretch 1.0:99:0.1", {"--stretch", "1.0:99:0.1"}},
      {"accuracy " + d / "missing.pyp" + " --direction course -o " + out, {d / "missing.pyp"}},
      {acc + "--strip-args '--bogus'", {"--strip-args", "--bogus"}},
      {acc + "--strip-args '--clamp 0.06'", {"--strip-args", "--clamp"}},
      {acc + "--sim-args '--dt -1'", {"--sim-args", "--dt", "'-1'"}},
      {acc + "--sim-args '--integrator euler'", {"--sim-args", "--integrator", "euler"}},
      {acc + "--baked " + f.dataset, {"--baked", f.dataset, "not a yarnhom baked file"}},
      {acc + "--dataset " + f.baked, {"--dataset", f.baked}},
      {"study table5 " + pat + " -o " + out + " --size 0,0", {"--size", "0,0"}},
      {"study table5 " + pat + " " + d / "missing.pyp" + " -o " + out, {d / "missing.pyp"}},
      {"study bake-resolution " + pat + " -o " + out + " --sim-args '--tol nan'", {"--sim-args", "--tol", "nan"}},
      {"study strip-width " + pat + " -o " + out + " --widths 0.02 --length 1e9", {"--size", "1e+09"}},
      {"study strip-width " + pat + " -o " + out + " --baked " + f.dataset, {"--baked", f.dataset}},
      {"study rve-size " + pat + " -o " + out + " --strip-args '--newton bogus'", {"--strip-args", "--newton", "bogus"}},
  };
  for (const Case& c : cases) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = run_cli_limited(c.args, 30);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_TRUE(refused(r.status)) << r.status << " " << c.args << "\n" << r.out;
    EXPECT_LT(s, 1.0) << c.args;
    for (const std::string& w : c.words) EXPECT_NE(r.out.find(w), std::string::npos) << c.args << ": no '" << w << "'\n" << r.out;
    EXPECT_EQ(r.out.find("logs/"), std::string::npos) << c.args << ": a stage ran\n" << r.out;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
}

// Issue 32 item 10: a strip of a pattern whose rest yarn is straight (stocktiny, the built-in
// patterns) does not hold together unless its clamps hold nearly all of it: refused at once with
// the reason and a size that works, instead of 300 Newton iterations and exit 2 after 45 s.
// (That such a wale strip runs: CliStrip.KilledAndRerunGivesTheSameForceCurve.)
TEST(Hardening3, StripsThatCannotHoldTogetherAreRefusedAtOnceWithTheReason) {
  yarnhom::test::TempDir d("h3_strip");
  const std::string tiny = pattern_file(), out = d / "s";
  for (const std::string& args : std::vector<std::string>{tiny + " --size 0.01,0.02 --stretch 1.0:1.05:0.05", tiny + " --size 0.0035,0.004 --clamp 0.0012",
        "plain --size 0.004,0.008 --clamp 0.001"}) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = run_cli_limited("strip " + args + " --no-plots -o " + out, 30);
    EXPECT_TRUE(refused(r.status)) << r.status << " " << args << "\n" << r.out;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0) << args;
    for (const char* w : {"straight", "a course strip of it does not hold at any size", "--direction wale --size"})
      EXPECT_NE(r.out.find(w), std::string::npos) << args << ": no '" << w << "'\n" << r.out;
  }
  // A wale strip with more than two courses between its clamps.
  const auto r = run_cli_limited("strip " + tiny + " --direction wale --size 0.0035,0.0053 --clamp 0.0009 --no-plots -o " + out, 30);
  EXPECT_TRUE(refused(r.status)) << r.out;
  EXPECT_NE(r.out.find("at most 2 courses between the clamps"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out));
  // A pattern with rest curvatures passes the check (accuracy makes strip's checks first, then
  // refuses its -o under a regular file).
  const std::string curved = d / "curved.pyp";
  yarnhom::test::write_curved_pattern(curved);
  std::ofstream(d / "file") << "x";
  const auto c = run_cli_limited("accuracy " + curved + " --direction course --size 0.01,0.02 -o " + d / "file/x", 30);
  EXPECT_TRUE(refused(c.status)) << c.out;
  EXPECT_EQ(c.out.find("straight"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("not a folder"), std::string::npos) << c.out;
}
