// `yarnhom sim` and `yarnhom export-hylc` end to end: the stretch scene on a HYLC material JSON
// writes force per clamp width equal to the material's stress at the middle; a drape with a
// trained and baked model stays finite for 90 steps of 1/30 s and ends resting on the sphere,
// and off centre stays on it with friction and slides off without;
// the baked model exported to HYLC's format simulates the same; a scene file with a moving
// handle runs; the renderer puts a moving capsule and a moving mesh collider where the
// simulator has them at each frame; bad inputs are refused with the file, key or option named.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include "tests/common/csv_rows.hpp"
#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

yarnhom::test::CliResult run(const std::string& args) { return yarnhom::test::run_cli(args); }

std::string tmpdir(const char* name) {
  fs::path d = fs::temp_directory_path() / ("yarnhom_sim_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

std::vector<std::vector<double>> read_csv(const std::string& path) { return yarnhom::test::read_csv_rows(path); }

std::vector<std::array<double, 3>> read_obj_vertices(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::array<double, 3>> v;
  while (std::getline(in, line))
    if (line.rfind("v ", 0) == 0) {
      std::array<double, 3> p;
      std::sscanf(line.c_str(), "v %lf %lf %lf", &p[0], &p[1], &p[2]);
      v.push_back(p);
    }
  return v;
}

// A homogeneous HYLC material: 20 S^2 + 8 S^3 along x, 12 S^2 along y, 4 S^2 shear, 6 u v
// coupling, quadratic bending (unit strain scales). Knots over [-1, 2].
std::string hylc_json(double density) {
  auto quad = [](int k, double a, double b) {
    std::ostringstream o;
    o << "{\"k\": " << k << ", \"t\": [";
    std::vector<double> t;
    for (int i = 0; i <= 12; ++i) t.push_back(-1 + 0.25 * i);
    std::ostringstream p, m;
    for (size_t i = 0; i < t.size(); ++i) {
      const double x = t[i];
      o << (i ? ", " : "") << x;
      p << (i ? ", " : "") << a * x * x + b * x * x * x;
      m << (i ? ", " : "") << 2 * a * x + 3 * b * x * x;
    }
    o << "], \"p\": [" << p.str() << "], \"m\": [" << m.str() << "]}";
    return o.str();
  };
  std::ostringstream j;
  j << "{\"density\": " << density << ", \"strain scale\": [1, 1, 1, 100, 100], \"coeffs\": {\"const\": 0, \"1D\": ["
    << quad(0, 20, 8) << ", " << quad(1, 4, 0) << ", " << quad(2, 12, 0) << ", " << quad(3, 2e-3, 0) << ", "
    << quad(4, 3e-3, 0) << "], \"2D\": [{\"k0\": 0, \"k1\": 2, \"tu\": [-1, 2], \"tv\": [-1, 2], "
    << "\"p\": [6, -12, -12, 24], \"mu\": [-6, -6, 12, 12], \"mv\": [-6, 12, -6, 12], \"muv\": [6, 6, 6, 6]}]}}";
  return j.str();
}

std::array<double, 3> centre_of_mass(const std::vector<std::array<double, 3>>& v) {
  std::array<double, 3> c = {0, 0, 0};
  for (const auto& p : v)
    for (int i = 0; i < 3; ++i) c[i] += p[i] / double(v.size());
  return c;
}

// A Python with matplotlib and numpy ("" when none), as sim looks for one.
std::string python_with_matplotlib() {
  for (const char* py : {"/usr/bin/python3", "python3"})
    if (std::system((std::string(py) + " -c 'import matplotlib, numpy' >/dev/null 2>&1").c_str()) == 0) return py;
  return "";
}

bool have_matplotlib() { return !python_with_matplotlib().empty(); }

// A 0.12 m square plate at height z (four triangles around its centre).
void write_plate(const std::string& path, double z, double y = 0) {
  std::ofstream f(path);
  for (auto [x, yy] : {std::pair{-0.06, -0.06}, {0.06, -0.06}, {0.06, 0.06}, {-0.06, 0.06}, {0.0, 0.0}})
    f << "v " << x << " " << y + yy << " " << z << "\n";
  f << "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
}

}  // namespace

TEST(CliSim, StretchReportsForcePerClampWidthAsCsvAndPng) {
  const std::string d = tmpdir("stretch");
  std::ofstream(d + "/mat.json") << hylc_json(0.3);
  auto r = run("sim stretch -o " + d + "/out --material " + d + "/mat.json --resolution 4 --direction wale");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto rows = read_csv(d + "/out/stretch.csv");
  ASSERT_EQ(rows.size(), 15u);
  for (size_t k = 1; k < rows.size(); ++k) {
    EXPECT_NEAR(rows[k][0], 1 + 0.05 * k, 1e-9);
    EXPECT_NEAR(rows[k][2], rows[k][9], 0.01 * rows[k][9]) << "stretch " << rows[k][0];  // N/m vs dPsi/ds_y
  }
  EXPECT_TRUE(fs::exists(d + "/out/frames/frame_0014.obj"));
  if (have_matplotlib()) {
    EXPECT_TRUE(fs::exists(d + "/out/stretch.png"));
    EXPECT_TRUE(fs::exists(d + "/out/renders/frame_0014.png"));
  }
  // What `yarnhom accuracy` reads (pipeline/accuracy_run.cpp): with --frames N, a `stretch` and a
  // `force_per_width_N_per_m` column with the ratios 1 + 0.7 k/N, and exactly N + 1 OBJ files
  // in frames/, one per row, in name order.
  r = run("sim stretch -o " + d + "/few --material " + d + "/mat.json --resolution 2 --frames 7 --render none -q");
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream csv(d + "/few/stretch.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("stretch,force_N,force_per_width_N_per_m,", 0), 0u) << header;
  const auto few = read_csv(d + "/few/stretch.csv");
  ASSERT_EQ(few.size(), 8u);
  for (size_t k = 0; k < few.size(); ++k) EXPECT_NEAR(few[k][0], 1 + 0.1 * k, 1e-9);
  std::vector<std::string> objs;
  for (const auto& e : fs::directory_iterator(d + "/few/frames")) objs.push_back(e.path().filename().string());
  std::sort(objs.begin(), objs.end());
  ASSERT_EQ(objs.size(), 8u);
  EXPECT_EQ(objs.front(), "frame_0000.obj");
  EXPECT_EQ(objs.back(), "frame_0007.obj");
  // Another size and load range (what `accuracy --size/--stretch` and the strip-width study
  // pass): the rows are the given ratios, the width of the report the given width.
  r = run("sim stretch -o " + d + "/sized --material " + d + "/mat.json --size 0.02,0.04 --stretch 1.0:1.2:0.1 --render none -q");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto sized = read_csv(d + "/sized/stretch.csv");
  ASSERT_EQ(sized.size(), 3u);
  for (size_t k = 0; k < sized.size(); ++k) {
    EXPECT_NEAR(sized[k][0], 1 + 0.1 * k, 1e-9);
    EXPECT_NEAR(sized[k][2], sized[k][1] / 0.02, 1e-7 * std::abs(sized[k][1] / 0.02) + 1e-12);  // N/m = N / width
  }
  EXPECT_TRUE(fs::exists(d + "/sized/frames/frame_0002.obj"));
  EXPECT_FALSE(fs::exists(d + "/sized/frames/frame_0003.obj"));
  for (const char* bad : {"--stretch 1.0:1.2:0.1 --frames 3", "--stretch 1.1:1.3:0.1", "--size 0.02", "--size 0.02,-0.04"}) {
    auto e = run("sim stretch -o " + d + "/bad --material " + d + "/mat.json --render none -q " + bad);
    EXPECT_NE(e.status, 0) << bad;
  }
  auto e = run("sim drape -o " + d + "/bad2 --material " + d + "/mat.json --size 0.02,0.04 -q");
  EXPECT_NE(e.status, 0);
  EXPECT_NE(e.out.find("--size, --stretch and --clamp apply to the built-in stretch scene only"), std::string::npos) << e.out;
  fs::remove_all(d);
}

// The stability claim with a model trained here (synthetic data, the paper's recipe) and
// baked; the synthetic energy is ~70 times softer than a knit, hence the light sheet.
TEST(CliSim, FactorizesWithTheKernelsChosenForTheCpu) {
  // numerics/blas_threads.hpp: `sim` starts again with OPENBLAS_CORETYPE when OpenBLAS's own
  // pick costs the factorization time; its header names the kernels it then runs with.
  if (std::getenv("OPENBLAS_CORETYPE")) GTEST_SKIP() << "OPENBLAS_CORETYPE is set: the user's choice is kept";
  const std::string d = tmpdir("kernels");
  std::ofstream(d + "/mat.json") << hylc_json(0.3);
  auto r = run("sim stretch -o " + d + "/out --material " + d + "/mat.json --resolution 2 --frames 1 --render none");
  ASSERT_EQ(r.status, 0) << r.out;
  const size_t at = r.out.find("OpenBLAS ");
  if (at == std::string::npos) GTEST_SKIP() << "the BLAS is not OpenBLAS: " << r.out.substr(0, 300);
  const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
  __builtin_cpu_init();
  const bool amd = __builtin_cpu_is("amd"), avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  for (const char* fallback : {" Prescott ", " Core2 ", " Nehalem ", " unknown "}) {
    if (avx2) {
      EXPECT_EQ(line.find(fallback), std::string::npos) << "an AVX2 CPU left with a fallback set: " << line;
    }
  }
  if (amd && avx2 && __builtin_cpu_supports("avx512f")) {
    EXPECT_NE(line.find(" Zen "), std::string::npos) << "an AMD CPU with AVX-512 not on OpenBLAS's Zen kernels: " << line;
  }
}

TEST(CliSim, HeaderNamesTheLinearSolver) {
  const std::string d = tmpdir("solver");
  std::ofstream(d + "/mat.json") << hylc_json(0.3);
  auto r = run("sim stretch -o " + d + "/a --material " + d + "/mat.json --resolution 2 --frames 1 --render none");
  ASSERT_EQ(r.status, 0) << r.out;
  // A quasi-static stretch factors (CHOLMOD, or Eigen's LDL^T in a build without it), GPU or not.
  EXPECT_TRUE(r.out.find("; solver cholmod;") != std::string::npos || r.out.find("; solver ldlt;") != std::string::npos)
      << r.out.substr(0, 400);
  r = run("sim drape -o " + d + "/b --material " + d + "/mat.json --density 0.3 --resolution 2 --frames 1 --render none --solver pcg");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("; solver pcg;"), std::string::npos) << r.out.substr(0, 400);
}

TEST(CliSim, DrapeWithATrainedModelIsStableAndExportRoundTrips) {
  const std::string d = tmpdir("drape");
  ASSERT_EQ(run("synth -o " + d + "/d.h5").status, 0);
  auto r = run("train-all " + d + "/d.h5 -o " + d + "/m.h5 -q");
  ASSERT_EQ(r.status, 0) << r.out;
  ASSERT_EQ(run("bake " + d + "/m.h5 -o " + d + "/b.h5").status, 0);
  // A baked file from synthetic data carries no areal density: gravity scenes refuse to guess.
  r = run("sim drape -o " + d + "/x --material " + d + "/b.h5");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("--density"), std::string::npos) << r.out;
  r = run("sim drape -o " + d + "/drape --material " + d + "/b.h5 --density 0.02 --resolution 12 --render none -q");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto steps = read_csv(d + "/drape/steps.csv");
  ASSERT_EQ(steps.size(), 90u);
  for (const auto& s : steps)
    for (double v : s) ASSERT_TRUE(std::isfinite(v));
  EXPECT_LT(steps.back()[8], 0.05) << "max speed at the end, m/s";
  // Resting on the sphere (radius 0.15 at the origin): every vertex outside it, the sheet's
  // centre on top of it within a few millimetres.
  const auto v = read_obj_vertices(d + "/drape/frames/frame_0090.obj");
  ASSERT_EQ(v.size(), 13u * 13u);
  for (const auto& p : v) EXPECT_GT(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), 0.15);
  const auto& c = v[6 * 13 + 6];
  EXPECT_NEAR(c[2], 0.15, 0.005);
  EXPECT_LT(std::hypot(c[0], c[1]), 0.01);
  EXPECT_GT(centre_of_mass(v)[2], 0.0);

  // Off centre by 6 cm (a scene file with one global friction coefficient): the overhang drags
  // the sheet off a frictionless sphere; with mu = 0.3 it stays draped over it, at rest.
  std::ofstream(d + "/off.json") << R"({
    "mesh": {"rectangle": {"width": 0.5, "height": 0.5, "nx": 12, "ny": 12}},
    "position": {"translate": [-0.19, -0.25, 0.2]},
    "areal_density": 0.02,
    "colliders": [{"sphere": {"center": [0, 0, 0], "radius": 0.15}}, {"plane": {"point": [0, 0, -0.15], "normal": [0, 0, 1]}}],
    "friction": 0.3, "frames": 90, "render": []
  })";
  r = run("sim " + d + "/off.json -o " + d + "/off --material " + d + "/b.h5 -q");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto off = read_csv(d + "/off/steps.csv");
  ASSERT_EQ(off.size(), 90u);
  // At rest up to the creep of steps that end within the Newton tolerance (docs/benchmarks.md,
  // the drape with friction): measured 5-15 mm/s from frame 60 to 150, against 1.2 m/s at
  // frame 10.
  EXPECT_LT(off.back()[8], 0.02) << "max speed at the end, m/s";
  const auto on = centre_of_mass(read_obj_vertices(d + "/off/frames/frame_0090.obj"));
  EXPECT_GT(on[2], 0.0) << "centre of mass above the sphere's centre";
  EXPECT_LT(std::hypot(on[0], on[1]), 0.05);
  r = run("sim " + d + "/off.json -o " + d + "/off0 --material " + d + "/b.h5 -q --friction 0 --frames 60");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto slid = centre_of_mass(read_obj_vertices(d + "/off0/frames/frame_0060.obj"));
  EXPECT_LT(slid[2], -0.1) << "frictionless: on the floor";
  EXPECT_GT(std::hypot(slid[0], slid[1]), 0.15);

  // export-hylc, then the same few drape frames from the JSON and from the baked file.
  r = run("export-hylc " + d + "/b.h5 -o " + d + "/m.json");
  EXPECT_EQ(r.status, 1) << r.out;  // no density in the file, none given
  ASSERT_EQ(run("export-hylc " + d + "/b.h5 -o " + d + "/m.json --density 0.02").status, 0);
  const std::string few = " --resolution 6 --frames 5 --render none -q";
  ASSERT_EQ(run("sim drape -o " + d + "/db --material " + d + "/b.h5 --density 0.02" + few).status, 0);
  ASSERT_EQ(run("sim drape -o " + d + "/dj --material " + d + "/m.json" + few).status, 0);
  const auto a = read_obj_vertices(d + "/db/frames/frame_0005.obj"), b = read_obj_vertices(d + "/dj/frames/frame_0005.obj");
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k)
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[k][i], b[k][i], 1e-6);
  fs::remove_all(d);
}

TEST(CliSim, SceneFileWithAMovingHandleRuns) {
  const std::string d = tmpdir("scene");
  std::ofstream(d + "/mat.json") << hylc_json(0.3);
  std::ofstream(d + "/scene.json") << R"({
    "mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 6, "ny": 3}},
    "material": "mat.json",
    "pins": [{"rest_box": [0, 0, 0, 0.1]}],
    "handles": [{"select": {"rest_box": [0.2, 0, 0.2, 0.1]}, "path": [[0, 0, 0, 0], [0.2, 0.02, 0, 0.05]]}],
    "colliders": [{"plane": {"point": [0, 0, -0.3], "normal": [0, 0, 1]}}],
    "damping": {"rayleigh_alpha": 0.5, "air": 0.1},
    "dt": 0.05, "frames": 6, "render": []
  })";
  auto r = run("sim " + d + "/scene.json -o " + d + "/out -q");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto v = read_obj_vertices(d + "/out/frames/frame_0006.obj");
  ASSERT_EQ(v.size(), 7u * 4u);
  EXPECT_NEAR(v[6][0], 0.22, 1e-9);  // the handle's corner moved by the path's end offset
  EXPECT_NEAR(v[6][2], 0.05, 1e-9);
  EXPECT_NEAR(v[0][0], 0.0, 1e-12);  // pinned
  // The same scene with the one-solve step, the Newton tolerance's norm named, and ARCSim's step.
  for (const char* integ : {"linearized", "baraff-witkin"}) {
    std::ifstream in(d + "/scene.json");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.replace(text.rfind('}'), 1, std::string(R"(, "integrator": ")") + integ +
                                        R"(", "newton": {"tolerance_norm": "max"}})");
    std::ofstream(d + "/scene_" + integ + ".json") << text;
    r = run("sim " + d + "/scene_" + integ + ".json -o " + d + "/out_" + integ + " -q");
    ASSERT_EQ(r.status, 0) << integ << ": " << r.out;
    const auto w = read_obj_vertices(d + "/out_" + integ + "/frames/frame_0006.obj");
    ASSERT_EQ(w.size(), 7u * 4u);
    EXPECT_NEAR(w[6][0], 0.22, 1e-9) << integ;
  }
  // A stretch report along a zero axis (issue 32 item 7: it exited 0 with every force 0).
  std::ofstream(d + "/zero_axis.json") << R"({"mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 2, "ny": 2}},
    "material": "mat.json", "handles": [{"select": {"vertices": [0]}, "path": [[0, 0, 0, 0], [1, 0.01, 0, 0]]}],
    "stretch_report": {"handle": 0, "axis": [0, 0, 0], "length": 0.2, "width": 0.1, "middle": [0.1, 0.05]}})";
  r = run("sim " + d + "/zero_axis.json -o " + d + "/zero -q");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("key 'stretch_report.axis': must be a nonzero, finite direction"), std::string::npos) << r.out;
  std::ofstream(d + "/bad_norm.json") << R"({"mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 2, "ny": 2}},
    "material": "mat.json", "newton": {"tolerance_norm": "l2"}})";
  r = run("sim " + d + "/bad_norm.json -o " + d + "/bad -q");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("key 'newton.tolerance_norm'"), std::string::npos) << r.out;
  fs::remove_all(d);
}

TEST(CliSim, RendersDrawMovingCollidersWhereTheSimulatorHasThem) {
  // A sheet floating (no gravity) over a plate that rises frame by frame (OBJ frames 0.1 s
  // apart, scaled by 2 and moved 1 cm up) beside a capsule moving away along y.
  const std::string d = tmpdir("movers");
  std::ofstream(d + "/mat.json") << hylc_json(0.3);
  for (int k = 0; k < 3; ++k) write_plate(d + "/p" + std::to_string(k) + ".obj", -0.05 + 0.01 * k);
  std::ofstream(d + "/scene.json") << R"({
    "mesh": {"rectangle": {"width": 0.1, "height": 0.1, "nx": 4, "ny": 4}}, "material": "mat.json",
    "position": {"translate": [-0.05, -0.05, 0]}, "gravity": [0, 0, 0],
    "colliders": [{"mesh": {"frames": ["p0.obj", "p1.obj", "p2.obj"], "frame_dt": 0.1, "scale": 2, "translate": [0, 0, 0.01]}},
                  {"capsule": {"a": [-0.1, 0.3, 0], "b": [0.1, 0.3, 0], "radius": 0.01, "path": [[0, 0, 0, 0], [0.3, 0, 0.12, 0]]}}],
    "dt": 0.05, "frames": 6, "render": [3, 6]
  })";
  auto r = yarnhom::test::run_shell("YARNHOM_NO_VIDEO=1 " + std::string(YARNHOM_BINARY) + " sim " + d + "/scene.json -o " + d + "/out -q");
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(d + "/out/scene_info.json");
  const std::string info((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(info.find("\"frame_time\": 0.05"), std::string::npos) << info;
  EXPECT_NE(info.find("\"path\""), std::string::npos) << info;
  EXPECT_NE(info.find(fs::absolute(d + "/p2.obj").lexically_normal().string()), std::string::npos) << info;
  // Nothing blocked the obstacles: steps.csv's last column, obstacle_lag_m, is 0 at every step.
  const auto steps = read_csv(d + "/out/steps.csv");
  ASSERT_EQ(steps.size(), 6u);
  for (const auto& row : steps) {
    ASSERT_EQ(row.size(), 24u);
    EXPECT_EQ(row.back(), 0.0);
  }
  const std::string py = python_with_matplotlib();
  if (py.empty()) GTEST_SKIP() << "no Python with matplotlib: the renders are not drawn";
  EXPECT_TRUE(fs::exists(d + "/out/renders/frame_0003.png"));
  EXPECT_TRUE(fs::exists(d + "/out/renders/frame_0006.png"));
  // The renderer's colliders at frames 0, 3 and 6 (t = 0, 0.15, 0.3 s): the capsule's end a
  // (y = 0.3 + 0.4 t) and the plate's centre (z = 2 (-0.05 + 0.1 t) + 0.01, held at the last
  // frame from t = 0.2 s), as the simulator moves them (sim/obstacles.cpp).
  const std::string script = "import sys, json; sys.path.insert(0, '" + std::string(YARNHOM_SOURCE_DIR) +
                             "/scripts/plot'); import render_sim as r; out = '" + d +
                             "/out'; info = json.load(open(out + '/scene_info.json')); "
                             "ms = [r.MeshCollider(c['mesh'], out) for c in info['colliders'] if 'mesh' in c]\n"
                             "for f in (0, 3, 6):\n"
                             "  p = {c[0]: c for c in r.collider_poses(info, ms, r.frame_time(info, f))}\n"
                             "  print('%.9f %.9f' % (p['capsule'][1][1], p['mesh'][1][:, :, 2].max()))\n";
  std::ofstream(d + "/poses.py") << script;
  r = yarnhom::test::run_shell(py + " " + d + "/poses.py");
  ASSERT_EQ(r.status, 0) << r.out;
  std::istringstream lines(r.out);
  for (double t : {0.0, 0.15, 0.3}) {
    double cap_y = 0, plate_z = 0;
    ASSERT_TRUE(lines >> cap_y >> plate_z) << r.out;
    EXPECT_NEAR(cap_y, 0.3 + 0.4 * t, 1e-9) << "t = " << t;
    EXPECT_NEAR(plate_z, 2 * (-0.05 + 0.1 * std::min(t, 0.2)) + 0.01, 1e-9) << "t = " << t;
  }
  fs::remove_all(d);
}

TEST(CliSim, BadInputsAreRefusedNamingTheProblem) {
  const std::string d = tmpdir("bad");
  std::ofstream(d + "/mat.json") << hylc_json(0.0);
  auto r = run("sim hang -o " + d + "/o --material " + d + "/mat.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("areal density"), std::string::npos) << r.out;
  std::ofstream(d + "/scene.json") << R"({"mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 2, "ny": 2}}, "dt": -1})";
  r = run("sim " + d + "/scene.json -o " + d + "/o --material " + d + "/mat.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find(d + "/scene.json: key 'dt'"), std::string::npos) << r.out;
  std::ofstream(d + "/scene2.json") << R"({"mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 2, "ny": 2}}, "colliders": [{"cube": {}}]})";
  r = run("sim " + d + "/scene2.json -o " + d + "/o --material " + d + "/mat.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("colliders[0].cube"), std::string::npos) << r.out;
  std::ofstream(d + "/scene3.json") << R"({"mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 2, "ny": 2}}, "friction": -0.1})";
  r = run("sim " + d + "/scene3.json -o " + d + "/o --material " + d + "/mat.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find(d + "/scene3.json: key 'friction': must be >= 0"), std::string::npos) << r.out;
  std::ofstream(d + "/scene4.json") << R"({"mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 2, "ny": 2}},
    "colliders": [{"plane": {"point": [0, 0, -1], "normal": [0, 0, 1]}, "friction": "rough"}]})";
  r = run("sim " + d + "/scene4.json -o " + d + "/o --material " + d + "/mat.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("key 'colliders[0].friction': must be a number"), std::string::npos) << r.out;
  std::ofstream(d + "/scene5.json") << R"({"mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 2, "ny": 2}},
    "friction": {"mu": 0.3, "eps": 1}})";
  r = run("sim " + d + "/scene5.json -o " + d + "/o --material " + d + "/mat.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("key 'friction.eps': unknown key"), std::string::npos) << r.out;
  r = run("sim drape -o " + d + "/o --material " + d + "/mat.json --friction -1");
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("--friction"), std::string::npos) << r.out;
  for (const std::string o : {"--pcg-tolerance 0", "--pcg-tolerance 0.9", "--solver qr"}) {
    r = run("sim drape -o " + d + "/o --material " + d + "/mat.json " + o);
    EXPECT_NE(r.status, 0) << o << ": " << r.out;
    EXPECT_NE(r.out.find(o.substr(0, o.find(' '))), std::string::npos) << r.out;
  }
  // The GPU solver: refused naming it where the build has no CUDA or the machine no GPU, else it runs.
  r = run("sim drape -o " + d + "/o --material " + d +
          "/mat.json --density 0.3 --resolution 4 --frames 1 --render none --solver pcg-cuda");
  if (r.status != 0) {
    EXPECT_TRUE(r.out.find("pcg-cuda: this build has no CUDA") != std::string::npos ||
                r.out.find("pcg-cuda: no CUDA GPU can be used") != std::string::npos) << r.out;
  } else {
    EXPECT_NE(r.out.find("pcg-cuda (block Jacobi"), std::string::npos) << r.out;
  }
  r = run("sim tumble -o " + d + "/o --material " + d + "/mat.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("not a built-in scene"), std::string::npos) << r.out;
  r = run("sim drape -o " + d + "/o");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("--material"), std::string::npos) << r.out;
  // A body OBJ for the T-shirt: only for tshirt, and not through its panels (a plate in front
  // of the torso at y = 0.25 m, where the front panel starts at 0.16 m).
  write_plate(d + "/front.obj", 1.0, 0.25);
  r = run("sim drape -o " + d + "/o --material " + d + "/mat.json --body " + d + "/front.obj");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("--body applies to the built-in tshirt scene only"), std::string::npos) << r.out;
  r = run("sim tshirt -o " + d + "/o --material " + d + "/mat.json --body " + d + "/front.obj");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("--body: " + d + "/front.obj: vertex 1"), std::string::npos) << r.out;
  fs::remove_all(d);
}

// --profile prints the step's named parts (core/scope_profile.hpp): one line per part with its
// ms per step and calls per step, the element derivatives and, with self-collision, the broad
// phase's region builds among them; without --profile none.
TEST(CliSim, ProfilePrintsTheStepsNamedParts) {
  const std::string d = tmpdir("profile");
  std::ofstream(d + "/mat.json") << hylc_json(0.3);
  const std::string common = "sim fold -o " + d + "/o --material " + d + "/mat.json --resolution 8 --frames 3 "
                             "--integrator linearized --render none --no-frames -q";
  auto r = run(common + " --profile");
  ASSERT_EQ(r.status, 0) << r.out;
  const size_t at = r.out.find("profile parts (ms per step");
  ASSERT_NE(at, std::string::npos) << r.out;
  std::istringstream lines(r.out.substr(at));
  std::string line;
  std::getline(lines, line);
  std::map<std::string, std::pair<double, double>> parts;
  while (std::getline(lines, line)) {
    double ms = -1, calls = -1;
    char name[200] = {};
    if (std::sscanf(line.c_str(), " %lf %lf %199[^\n]", &ms, &calls, name) != 3) break;
    parts[name] = {ms, calls};
  }
  for (const char* part : {"derivatives: elements", "assembly: potential derivatives", "broad phase: a region built",
                           "line search: CCD of the step", "energy: elements"}) {
    ASSERT_TRUE(parts.count(part)) << part << "\n" << r.out;
    EXPECT_GE(parts[part].first, 0.0) << part;
    EXPECT_GT(parts[part].second, 0.0) << part;
  }
  EXPECT_DOUBLE_EQ(parts["assembly: potential derivatives"].second, 1.0);  // one solve per step
  r = run(common);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out.find("profile parts"), std::string::npos);
}
