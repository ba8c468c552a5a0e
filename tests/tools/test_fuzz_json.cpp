// Issue 32: the seeded fuzz test extended to the inputs of the newer commands. A few hundred
// mutants of a sim scene file and of a HYLC material JSON, each read (and the scene's mesh and
// the material used), must be read or refused with a message that names the file: never a
// crash, a hang, std::bad_alloc or the JSON library's own text. Then hostile values of the
// options of sim, strip, export-hylc, fit-splines, accuracy and study go through the program:
// no signal, no hang, a refusal within 5 s in one line. The issue's inputs come first as
// regression cases (a 1e8 x 1e8 rectangle, "width": 1e999, a million brackets, strip --size
// 1e9,1e9, accuracy --size 0,0.1, --strip-args --bogus, --sim-args '--dt -1', study --size 0,0).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "core/baked.hpp"
#include "material/hylc_material.hpp"
#include "material/material_source.hpp"
#include "sim/scene_json.hpp"
#include "tests/common/fuzz_kinds.hpp"
#include "tests/common/run_cli.hpp"
#include "tests/common/small_files.hpp"

namespace fs = std::filesystem;
using namespace yarnhom;
using Rng = std::mt19937_64;

namespace {

int pick(Rng& rng, int n) { return int(std::uniform_int_distribution<int>(0, n - 1)(rng)); }

const char* kScene = R"({
  "name": "fuzz",
  "mesh": {"rectangle": {"width": 0.2, "height": 0.1, "nx": 4, "ny": 2}},
  "position": {"rotate_deg": [0, 10, 0], "translate": [0, 0, 0.3]},
  "areal_density": 0.3, "gravity": [0, 0, -9.81],
  "pins": [{"rest_box": [0, 0, 0.001, 0.1]}],
  "handles": [{"select": {"vertices": [4, 9]}, "path": [[0, 0, 0, 0], [1, 0.01, 0, 0]]}],
  "colliders": [{"sphere": {"center": [0.1, 0.05, 0], "radius": 0.05}, "friction": 0.2},
                {"plane": {"point": [0, 0, -1], "normal": [0, 0, 1]}}],
  "barrier": {"dhat": 0.001, "kappa": 100},
  "friction": {"mu": 0.3, "eps_v": 0.001, "updates": 1},
  "damping": {"rayleigh_alpha": 0.1, "rayleigh_beta": 0.001, "air": 0.01},
  "integrator": "newton", "dt": 0.0333, "substeps": 2, "frames": 3,
  "newton": {"tolerance": 1e-6, "tolerance_norm": "rms", "max_iterations": 50},
  "render": [0, 3],
  "stretch_report": {"handle": 1, "axis": [1, 0, 0], "length": 0.2, "width": 0.1, "middle": [0.1, 0.05]}
})";

const std::vector<std::string> kHostileJson = {
    "1e999", "-1e999", "1e400", "0", "-0", "-1", "1e300", "-1e300", "1e-300", "100000000", "2147483648",
    "-2147483649", "99999999999999999999999", "1.5", "3", "1e15", "\"x\"", "[]", "{}", "null", "true", "nan",
    "inf", "[0, 0]", "[1e999, 0, 0]", "\"\"", "0.0000001", "-1e-320", "5e-324"};

// The positions of the JSON numbers in a text.
std::vector<std::pair<size_t, size_t>> numbers_in(const std::string& t) {
  std::vector<std::pair<size_t, size_t>> out;
  for (size_t i = 0; i < t.size();) {
    const bool start = (std::isdigit(static_cast<unsigned char>(t[i])) || t[i] == '-') && (i == 0 || !std::isalnum(static_cast<unsigned char>(t[i - 1])));
    if (!start) {
      ++i;
      continue;
    }
    size_t j = i + 1;
    while (j < t.size() && (std::isdigit(static_cast<unsigned char>(t[j])) || t[j] == '.' || t[j] == 'e' || t[j] == 'E' || t[j] == '-' || t[j] == '+')) ++j;
    out.emplace_back(i, j - i);
    i = j;
  }
  return out;
}

std::string mutate_json(const std::string& text, Rng& rng) {
  std::string t = text;
  const int n = 1 + pick(rng, 3);
  for (int m = 0; m < n; ++m) {
    const auto nums = numbers_in(t);
    switch (pick(rng, 7)) {
      case 0:
      case 1:
      case 2: {  // a number becomes a hostile value
        if (nums.empty()) break;
        const auto [at, len] = nums[pick(rng, int(nums.size()))];
        t.replace(at, len, kHostileJson[pick(rng, int(kHostileJson.size()))]);
        break;
      }
      case 3:  // a character deleted
        if (!t.empty()) t.erase(pick(rng, int(t.size())), 1);
        break;
      case 4: {  // a structural character inserted
        const std::string c = "{}[],:\"0e-";
        t.insert(t.begin() + pick(rng, int(t.size()) + 1), c[pick(rng, int(c.size()))]);
        break;
      }
      case 5:  // truncated
        t.resize(pick(rng, int(t.size()) + 1));
        break;
      case 6: {  // a number nested deep
        if (nums.empty()) break;
        const auto [at, len] = nums[pick(rng, int(nums.size()))];
        const int depth = pick(rng, 2) ? 300 : 3;
        t.replace(at, len, std::string(depth, '[') + t.substr(at, len) + std::string(depth, ']'));
        break;
      }
    }
  }
  return t;
}

void use_scene(const std::string& path) {
  const sim::Scene s = sim::read_scene_json(path);
  double sum = 0;
  for (int v = 0; v < s.mesh.num_vertices(); ++v) sum += s.mesh.x.row(v).norm();
  (void)sum;
}

void use_hylc(const std::string& path) {
  const LoadedMaterial m = load_material(path);
  for (double a : {0.0, 0.05, 0.5}) {
    Strain6 s;
    s << a, 0.5 * a, -a, 20 * a, 5 * a, -10 * a;
    m.fn(s);
  }
}

// Runs args under 20 s: no signal, no hang; a refusal is one "yarnhom: error:" line within 5 s.
void expect_no_crash(const std::string& args, bool must_refuse, int* refused) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = yarnhom::test::run_cli_limited(args, 20);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(r.status, 128) << args << ": ended by a signal or hung\n" << r.out;
  if (must_refuse) {
    EXPECT_NE(r.status, 0) << args << "\n" << r.out;
  }
  if (r.status == 0) return;
  ++*refused;
  EXPECT_LT(s, 5.0) << args;
  for (const char* lib : {"std::", "bad_alloc", "json.exception", "filesystem error", "basic_filebuf"})
    EXPECT_EQ(r.out.find(lib), std::string::npos) << args << ": library text\n" << r.out;
}

}  // namespace

TEST(Fuzz, SceneAndHylcJsonAndTheNewCommandsOptionsAreReadOrRefusedCleanly) {
  const auto t0 = std::chrono::steady_clock::now();
  yarnhom::test::TempDir d("fuzz_json");
  const fs::path keep = fs::temp_directory_path() / "yarnhom_fuzz_failures";
  fs::create_directories(keep);
  const auto files = yarnhom::test::write_small_files(d);
  Rng rng(20261127);
  const int kScenes = 300, kHylc = 150;

  // Scene files: the issue's cases first.
  yarnhom::test::Kind scene{"scene", use_scene, {}};
  const std::vector<std::string> scene_corpus = {
      R"({"mesh": {"rectangle": {"width": 1, "height": 1, "nx": 100000000, "ny": 100000000}}})",
      R"({"mesh": {"rectangle": {"width": 1e999, "height": 1, "nx": 2, "ny": 2}}})",
      R"({"mesh": {"rectangle": {"width": 1e-300, "height": 1e300, "nx": 2, "ny": 2}}})",
      std::string(1000000, '[') + std::string(1000000, ']'),
      R"({"mesh": {"rectangle": {"width": 1, "height": 1, "nx": 2, "ny": 2}}, "stretch_report": {"handle": 0, "axis": [0, 0, 0], "length": 1, "width": 1, "middle": [0, 0]}, "pins": [{"vertices": [0]}]})",
      R"({"mesh": {"obj": "."}})"};
  for (int i = 0; i < kScenes; ++i) {
    const std::string p = d / ("scene" + std::to_string(i) + ".json");
    std::ofstream(p, std::ios::binary) << (i < int(scene_corpus.size()) ? scene_corpus[i] : mutate_json(kScene, rng));
    scene.mutants.push_back(p);
  }
  // HYLC material files, written from the small baked file.
  yarnhom::test::Kind hylc{"hylc", use_hylc, {}};
  {
    const std::string base = d / "hylc_base.json";
    write_hylc_material(base, hylc_from_baked(read_baked(files.baked), 0.3));
    std::ifstream in(base, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    for (int i = 0; i < kHylc; ++i) {
      const std::string p = d / ("hylc" + std::to_string(i) + ".json");
      std::ofstream(p, std::ios::binary) << (i == 0 ? text : mutate_json(text, rng));
      hylc.mutants.push_back(p);
    }
  }
  std::vector<std::string> failures;
  int refused[2] = {0, 0};
  for (const std::string& f : yarnhom::test::run_kind(scene, keep, &refused[0])) failures.push_back(f);
  for (const std::string& f : yarnhom::test::run_kind(hylc, keep, &refused[1])) failures.push_back(f);
  for (const std::string& f : failures) ADD_FAILURE() << f;
  EXPECT_GT(refused[0], kScenes / 3);
  EXPECT_GT(refused[1], kHylc / 4);
  const double read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // The options of the newer commands through the program. Runs that pass must be short: sim
  // runs one frame of a 2 x 2 sheet; strip names a missing pattern (checked after its options);
  // accuracy and study write to a path under a regular file (refused after their checks).
  std::ofstream(d / "file") << "x";
  const std::string curved = d / "curved.pyp";  // strip's checks pass it at any size: the options are what is tested
  yarnhom::test::write_curved_pattern(curved);
  const std::string missing = d / "missing.pyp", under_file = d / "file/out", out = d / "o";
  const std::string sim = "sim drape -q --frames 1 --resolution 2 --render none --no-frames --material " + files.baked +
                          " -o " + out + " ";
  const std::string stretch = "sim stretch -q --resolution 2 --no-frames --render none --material " + files.baked + " -o " + out + " ";
  struct Opt {
    std::string prefix, option;
  };
  const std::vector<Opt> opts = {
      {sim, "--dt"}, {sim, "--density"}, {sim, "--tol"}, {sim, "--rayleigh-alpha"}, {sim, "--rayleigh-beta"},
      {sim, "--air"}, {sim, "--friction"}, {sim, "--friction-eps-v"}, {sim, "--max-iterations"},
      {stretch + "--stretch 1.0:1.05:0.05", "--size"}, {stretch + "--size 0.02,0.04", "--stretch"},
      {stretch + "--stretch 1.0:1.05:0.05", "--clamp"},
      {"strip " + missing + " -o " + out, "--size"}, {"strip " + missing + " -o " + out, "--stretch"},
      {"strip " + missing + " -o " + out, "--clamp"}, {"strip " + missing + " -o " + out, "--connector-scale"},
      {"strip " + missing + " -o " + out, "--tolerance"}, {"strip " + missing + " -o " + out, "--rest-time-limit"},
      {"export-hylc " + files.baked + " -o " + d / "m.json", "--density"},
      {"export-hylc " + files.baked + " --density 0.3 -o " + d / "m.json", "--margin"},
      {"fit-splines " + files.dataset + " -o " + d / "s.h5", "--smoothing"},
      {"fit-splines " + files.dataset + " -o " + d / "s.h5", "--gradient-weight"},
      {"accuracy " + curved + " --direction wale -o " + under_file, "--size"},
      {"accuracy " + curved + " --direction wale -o " + under_file, "--stretch"},
      {"accuracy " + curved + " --direction wale -o " + under_file, "--spacing"},
      {"accuracy " + curved + " --direction wale -o " + under_file, "--epochs"},
      {"study table5 " + curved + " -o " + under_file, "--size"},
      {"study strip-width " + curved + " -o " + under_file, "--widths"},
      {"study strip-width " + curved + " -o " + under_file, "--length"}};
  const std::vector<std::string> values = {"nan", "inf", "-inf", "-1", "0", "1e300", "1e-300", "x", "''", "1e999",
                                           "2147483648", "0,0", "1e9,1e9", "0,0.1", "1.0:0.5:0.1", "1.0:10:1e-9",
                                           "1.0:1e300:1", "0.01", "3"};
  int through = 0, cli_refused = 0;
  // The issue's command lines first.
  for (const std::string& args :
       {"strip " + d / "missing.pyp" + " --size 1e9,1e9 -o " + out, "strip stockinette --size 1e9,1e9 -o " + out,
        "accuracy " + curved + " --direction wale -o " + out + " --size 0,0.1",
        "accuracy " + curved + " --direction wale -o " + out + " --strip-args '--bogus'",
        "accuracy " + curved + " --direction wale -o " + out + " --sim-args '--dt -1'",
        "accuracy " + curved + " --direction wale -o " + out + " --baked " + files.dataset,
        "study table5 " + curved + " -o " + out + " --size 0,0", "sim stretch --size 1e9,1e9 -o " + out + " --material " + files.baked,
        "sim " + d / "scene0.json" + " -o " + out + " --material " + files.baked,
        "sim " + d / "scene1.json" + " -o " + out + " --material " + files.baked}) {
    expect_no_crash(args, true, &cli_refused);
    ++through;
  }
  for (int i = 0; i < 60; ++i) {
    const Opt& o = opts[pick(rng, int(opts.size()))];
    const std::string args = o.prefix + " " + o.option + " " + values[pick(rng, int(values.size()))];
    // strip's missing pattern and accuracy's bad -o refuse what the options let through.
    const bool must = o.prefix.find(missing) != std::string::npos || o.prefix.find(under_file) != std::string::npos;
    expect_no_crash(args, must, &cli_refused);
    ++through;
  }
  // Random --strip-args and --sim-args: each refused before a stage starts.
  const std::vector<std::string> strip_opts = {"--clamp", "--tolerance", "--newton", "--max-iterations", "--bogus", "--connector-scale"};
  const std::vector<std::string> sim_opts = {"--dt", "--tol", "--integrator", "--friction", "--clamp", "--resolution", "--bogus"};
  for (int i = 0; i < 20; ++i) {
    const bool strip = i % 2 == 0;
    const auto& list = strip ? strip_opts : sim_opts;
    const std::string extra = list[pick(rng, int(list.size()))] + " " + values[pick(rng, int(values.size()))];
    expect_no_crash("accuracy " + curved + " --direction wale -o " + under_file + (strip ? " --strip-args '" : " --sim-args '") +
                        extra + "'",
                    true, &cli_refused);
    ++through;
  }
  EXPECT_FALSE(fs::exists(under_file));
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("fuzz: %zu scene, %zu HYLC mutants (refused %d, %d; %.1f s), %d command lines (refused %d), %.1f s in all\n",
              scene.mutants.size(), hylc.mutants.size(), refused[0], refused[1], read_s, through, cli_refused, total);
  EXPECT_LT(total, 60.0);
  if (failures.empty()) fs::remove_all(keep);
}
