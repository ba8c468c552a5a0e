// Issue 37's outputs end to end: a simulation's frames carry texture coordinates in [0, 1] and
// its rest shape in rest.obj, a step that ends unconverged (here at a Newton iteration cap of 1)
// is reported when it happens, one line, before the run's summary, and a run's video is written.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;

TEST(CliOutputs37, SimFramesHaveUnitTextureCoordinatesAndUnconvergedStepsAreReportedAtOnce) {
  const fs::path d = fs::temp_directory_path() / ("yarnhom_o37_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string ds = (d / "d.h5").string(), b = (d / "b.h5").string(), out = (d / "sim").string();
  ASSERT_EQ(yarnhom::test::run_cli("synth -o " + ds + " --preset quick").status, 0);
  ASSERT_EQ(yarnhom::test::run_cli("fit-splines " + ds + " -o " + b).status, 0);
  const auto r = yarnhom::test::run_cli("sim drape -o " + out + " --material " + b +
                                        " --density 0.3 --resolution 3 --frames 3 --max-iterations 1 --render none --threads 1");
  ASSERT_EQ(r.status, 0) << r.out;
  const size_t line = r.out.find("not converged to --tol after 1 Newton iteration(s) (the cap, --max-iterations)");
  ASSERT_NE(line, std::string::npos) << r.out;
  EXPECT_LT(line, r.out.find("step(s) not converged to --tol")) << "reported before the summary:\n" << r.out;

  std::ifstream f(fs::path(out) / "frames" / "frame_0003.obj");
  ASSERT_TRUE(f);
  int vt = 0;
  bool uv_line = false;
  for (std::string l; std::getline(f, l);) {
    uv_line |= l.rfind("# yarnhom uv: rest_m = origin + scale * vt;", 0) == 0;
    if (l.rfind("vt ", 0) != 0) continue;
    std::istringstream ss(l.substr(3));
    double u, v;
    ss >> u >> v;
    EXPECT_TRUE(u >= 0 && u <= 1 && v >= 0 && v <= 1) << l;
    ++vt;
  }
  EXPECT_EQ(vt, 16);  // 4 x 4 vertices
  EXPECT_TRUE(uv_line);
  EXPECT_TRUE(fs::is_regular_file(fs::path(out) / "rest.obj"));

  // The video of a run (CI sets YARNHOM_NO_VIDEO for every other test): written where ffmpeg
  // and matplotlib are, one line saying why not otherwise.
  const std::string out2 = (d / "video").string();
  const auto v = yarnhom::test::run_shell("env -u YARNHOM_NO_VIDEO " + std::string(YARNHOM_BINARY) + " sim drape -o " + out2 +
                                          " --material " + b + " --density 0.3 --resolution 3 --frames 2 --render 0 -q");
  ASSERT_EQ(v.status, 0) << v.out;
  const bool ffmpeg = yarnhom::test::run_shell("command -v ffmpeg").status == 0;
  if (v.out.find("no python3 with matplotlib") == std::string::npos) {
    if (ffmpeg)
      EXPECT_TRUE(fs::is_regular_file(fs::path(out2) / "sim.mp4")) << v.out;
    else
      EXPECT_NE(v.out.find("no ffmpeg found: no MP4 written"), std::string::npos) << v.out;
  }
  fs::remove_all(d);
}
