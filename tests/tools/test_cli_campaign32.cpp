// The findings of issue 32's acceptance campaign (tools/campaign, parts E-G; docs/hardening.md),
// each a regression case: a refusal that named neither the option nor the file, now does.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/common/run_cli.hpp"
#include "tests/common/small_files.hpp"

namespace fs = std::filesystem;
using yarnhom::test::run_cli_limited;

namespace {

// Refused within 5 s, in one "yarnhom: error:" line (or CLI11's) naming each of `words`.
void expect_refusal_naming(const std::string& args, const std::vector<std::string>& words) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = run_cli_limited(args, 30);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(r.status != 0 && r.status < 128) << r.status << " " << args << "\n" << r.out;
  EXPECT_LT(s, 5.0) << args;
  for (const std::string& w : words) EXPECT_NE(r.out.find(w), std::string::npos) << args << ": no '" << w << "'\n" << r.out;
  EXPECT_EQ(r.out.find("std::"), std::string::npos) << r.out;
}

}  // namespace

// sim stretch --clamp 3 said "stretch: the clamp band must lie in [0, length / 2)": neither the
// option nor its value nor the length.
TEST(Campaign32, SimStretchClampLongerThanHalfTheStripNamesTheOptionAndTheLength) {
  yarnhom::test::TempDir d("c32_clamp");
  const std::string baked = yarnhom::test::write_small_files(d).baked;
  const std::string base = "sim stretch -q --resolution 2 --render none --no-frames --density 0.3 --material " + baked +
                           " -o " + d / "o";
  expect_refusal_naming(base + " --clamp 3", {"--clamp 3", "0.1 m"});
  expect_refusal_naming(base + " --clamp 0.02 --size 0.02,0.04", {"--clamp 0.02", "0.04 m", "--size"});
  // accuracy hands --sim-args to the same check before any stage.
  const std::string pat = d / "curved.pyp";
  yarnhom::test::write_curved_pattern(pat);
  std::ofstream(d / "file") << "x";
  expect_refusal_naming("accuracy " + pat + " --direction wale -o " + d / "file/out" + " --sim-args '--clamp 1'", {"--clamp 1"});
  const auto r = run_cli_limited(base + " --clamp 0.01 --stretch 1.0:1.05:0.05", 60);
  EXPECT_EQ(r.status, 0) << r.out;  // a band shorter than half the length still runs
}

// fit-splines --smoothing 1e300 (or --gradient-weight 1e300) said "term 3: no monotone fit
// found", naming neither the dataset nor the option: the weights are bounded, and a fit that
// fails names the file and the weights.
TEST(Campaign32, FitSplinesWeightsAreBoundedAndAFailedFitNamesTheFile) {
  yarnhom::test::TempDir d("c32_fit");
  const std::string ds = yarnhom::test::write_small_files(d).dataset;
  for (const char* o : {"--smoothing", "--gradient-weight"})
    for (const char* v : {"1e300", "2e6"})
      expect_refusal_naming("fit-splines " + ds + " -o " + d / "s.h5 " + o + " " + v, {o, v, "[0, 1e6]"});
  EXPECT_FALSE(fs::exists(d / "s.h5"));
  const auto r = run_cli_limited("fit-splines " + ds + " -o " + d / "s.h5 --smoothing 1e6 --gradient-weight 1e6", 60);
  EXPECT_EQ(r.status, 0) << r.out;
}

// A scene whose plane lay above the sheet (a mutant's "point": [0, 0, 2147483648]) was refused
// with "vertex 0 starts inside collider 1": neither the scene file nor its key.
TEST(Campaign32, ASceneStartingInsideAColliderNamesTheFileAndTheCollider) {
  yarnhom::test::TempDir d("c32_collider");
  const std::string baked = yarnhom::test::write_small_files(d).baked;
  std::ofstream(d / "s.json") << R"({"mesh": {"rectangle": {"width": 0.1, "height": 0.1, "nx": 2, "ny": 2}}, )"
                              << R"("areal_density": 0.3, "colliders": [{"sphere": {"center": [5, 5, 5], "radius": 0.1}}, )"
                              << R"({"plane": {"point": [0, 0, 2147483648], "normal": [0, 0, 1]}}]})";
  expect_refusal_naming("sim " + d / "s.json -q --frames 1 --render none --material " + baked + " -o " + d / "o",
                        {d / "s.json", "colliders[1]", "outside"});
}

// study strip-width --widths 1e300 (or --length 0.01) was refused naming the strip stage's
// --size it became, not --widths or --length.
TEST(Campaign32, StripWidthStudyRefusalsNameItsOwnOptions) {
  yarnhom::test::TempDir d("c32_width");
  const std::string pat = d / "curved.pyp";
  yarnhom::test::write_curved_pattern(pat);
  std::ofstream(d / "file") << "x";
  const std::string base = "study strip-width " + pat + " -o " + d / "file/out";
  expect_refusal_naming(base + " --widths 1e300", {"--widths 1e+300", "--length"});
  expect_refusal_naming(base + " --widths 0.01,2147483648", {"--widths 2.14748e+09"});
  expect_refusal_naming(base + " --length 0.01", {"--widths", "--length 0.01"});
}
