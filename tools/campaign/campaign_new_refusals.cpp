// Part E of the hardening campaign (issue 32): the new commands refuse bad inputs cleanly.
// Hostile values of every floating, size and stretch option of sim, strip, export-hylc,
// fit-splines, accuracy and study (each value against each option: not sampled), random
// --strip-args and --sim-args, the issue's own command lines, seeded mutants of a scene file and
// of a HYLC material JSON run through `sim`, FIFOs named as every kind of input, and one
// corrupted byte of a baked file's first 4 KiB through `eval` (1D and 2D terms).
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "tools/campaign/campaign_parts.hpp"
#include "tools/campaign/campaign_util.hpp"

namespace campaign {

namespace {

int pick(std::mt19937_64& rng, int n) { return int(std::uniform_int_distribution<int>(0, n - 1)(rng)); }

const char* kScene = R"({
  "name": "campaign",
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

std::vector<std::pair<size_t, size_t>> numbers_in(const std::string& t) {
  std::vector<std::pair<size_t, size_t>> out;
  for (size_t i = 0; i < t.size();) {
    const bool start = (std::isdigit(static_cast<unsigned char>(t[i])) || t[i] == '-') &&
                       (i == 0 || !std::isalnum(static_cast<unsigned char>(t[i - 1])));
    if (!start) {
      ++i;
      continue;
    }
    size_t j = i + 1;
    while (j < t.size() && (std::isdigit(static_cast<unsigned char>(t[j])) || std::strchr(".eE-+", t[j]))) ++j;
    out.emplace_back(i, j - i);
    i = j;
  }
  return out;
}

// One to three edits: a number made hostile, a character deleted or inserted, the text cut, a
// number nested 3 or 300 deep.
std::string mutate_json(const std::string& text, std::mt19937_64& rng) {
  std::string t = text;
  for (int m = 0, n = 1 + pick(rng, 3); m < n; ++m) {
    const auto nums = numbers_in(t);
    switch (pick(rng, 7)) {
      case 0: case 1: case 2:
        if (!nums.empty()) {
          const auto [at, len] = nums[pick(rng, int(nums.size()))];
          t.replace(at, len, kHostileJson[pick(rng, int(kHostileJson.size()))]);
        }
        break;
      case 3: if (!t.empty()) t.erase(pick(rng, int(t.size())), 1); break;
      case 4: t.insert(t.begin() + pick(rng, int(t.size()) + 1), "{}[],:\"0e-"[pick(rng, 10)]); break;
      case 5: t.resize(pick(rng, int(t.size()) + 1)); break;
      case 6:
        if (!nums.empty()) {
          const auto [at, len] = nums[pick(rng, int(nums.size()))];
          const int depth = pick(rng, 2) ? 300 : 3;
          t.replace(at, len, std::string(depth, '[') + t.substr(at, len) + std::string(depth, ']'));
        }
        break;
    }
  }
  return t;
}

// Whether a sim run's tables hold a non-finite number.
bool nonfinite_in(const fs::path& dir) {
  for (const char* f : {"steps.csv", "stretch.csv"}) {
    std::string t = slurp((dir / f).string());
    std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return std::tolower(c); });
    if (t.find("nan") != std::string::npos || t.find("inf") != std::string::npos) return true;
  }
  return false;
}

// Option kinds and which of the hostile values each must refuse.
enum Kind { Pos, NonNeg, Unit, Tol, Margin, IntPos, IntNonNeg, Size, Stretch, Widths };
const std::vector<std::string> kValues = {"nan", "inf", "-inf", "-1", "0", "1e300", "1e-300", "x", "''", "1e999",
                                          "2147483648", "0,0", "1e9,1e9", "0,0.1", "1.0:0.5:0.1", "1.0:10:1e-9",
                                          "1.0:1e300:1", "0.01", "3"};
bool must_refuse(Kind k, const std::string& v) {
  for (const char* bad : {"nan", "inf", "-inf", "-1", "x", "''", "1e999"})
    if (v == bad) return true;
  const bool number = v.find_first_of(",:") == std::string::npos;
  switch (k) {
    case Pos: return !number || v == "0";
    case NonNeg: return !number;
    case Unit: return !number || v == "0" || v == "1e300" || v == "2147483648" || v == "3";
    case Tol: return !number || v == "0" || v == "1e300" || v == "2147483648" || v == "3";
    case Margin: return !number || v == "1e-300" || v == "1e300" || v == "2147483648";
    case IntPos: return !(v == "3");
    case IntNonNeg: return !(v == "3" || v == "0");
    case Size: return true;     // every value here is a bad WIDTH,LENGTH
    case Stretch: return true;  // and a bad 1.0:LAST:STEP
    case Widths: return !(v == "0.01" || v == "3");
  }
  return true;
}

}  // namespace

void part_e_refusals(const fs::path& work, const NewPartsOptions& opt, std::mt19937_64& rng) {
  const fs::path dir = fresh_model_dir(work / "new_refusals");
  auto p = [&](const std::string& f) { return (dir / f).string(); };
  run(cmd({"bake", p("m.h5"), "-o", p("b.h5"), "--res1d", "20", "--res2d", "8"}));
  run(cmd({"export-hylc", p("b.h5"), "--density", "0.3", "-o", p("hylc.json")}));
  std::ofstream(p("file")) << "x";
  const std::string B = p("b.h5"), D = p("d.h5"), out = p("o"), under_file = p("file/out"), pat = opt.check_pattern;
  Tally all;

  // E1. Every hostile value against every option.
  Tally t1;
  std::printf("E1. hostile option values (each of %zu values against each option)\n", kValues.size());
  const std::string sim = "sim drape -q --frames 1 --resolution 2 --render none --no-frames --threads 1 --material " + B +
                          " -o " + out + " ";
  const std::string stretch = "sim stretch -q --resolution 2 --no-frames --render none --threads 1 --material " + B +
                              " --density 0.3 -o " + out + " ";
  const std::string missing = p("missing.pyp");
  const std::string strip = "strip " + missing + " -o " + out + " ";
  const std::string acc = "accuracy " + pat + " --direction wale -o " + under_file + " ";
  struct Opt {
    std::string prefix, option;
    Kind kind;
    bool runs;  // valid values run the command for real (else the prefix fails after the options)
  };
  const std::vector<Opt> opts = {
      {sim + "--density 0.3", "--dt", Pos, true}, {sim, "--density", Pos, true},
      {sim + "--density 0.3", "--tol", Pos, true}, {sim + "--density 0.3", "--rayleigh-alpha", NonNeg, true},
      {sim + "--density 0.3", "--rayleigh-beta", NonNeg, true}, {sim + "--density 0.3", "--air", NonNeg, true},
      {sim + "--density 0.3", "--friction", NonNeg, true}, {sim + "--density 0.3", "--friction-eps-v", Pos, true},
      {sim + "--density 0.3", "--max-iterations", IntPos, true},
      {stretch + "--stretch 1.0:1.05:0.05", "--size", Size, true}, {stretch + "--size 0.02,0.04", "--stretch", Stretch, true},
      {stretch + "--stretch 1.0:1.05:0.05", "--clamp", NonNeg, true},
      {strip, "--size", Size, false}, {strip, "--stretch", Stretch, false}, {strip, "--clamp", Pos, false},
      {strip, "--connector-scale", Unit, false}, {strip, "--tolerance", Tol, false}, {strip, "--rest-time-limit", NonNeg, false},
      {"export-hylc " + B + " -o " + p("m.json"), "--density", Pos, true},
      {"export-hylc " + B + " --density 0.3 -o " + p("m.json"), "--margin", Margin, true},
      {"fit-splines " + D + " -o " + p("s.h5"), "--smoothing", NonNeg, true},
      {"fit-splines " + D + " -o " + p("s.h5"), "--gradient-weight", NonNeg, true},
      {acc, "--size", Size, false}, {acc, "--stretch", Stretch, false}, {acc, "--spacing", Pos, false},
      {acc, "--epochs", IntNonNeg, false},
      {"study table5 " + pat + " -o " + under_file, "--size", Size, false},
      {"study strip-width " + pat + " -o " + under_file, "--widths", Widths, false},
      {"study strip-width " + pat + " -o " + under_file, "--length", Pos, false}};
  for (const Opt& o : opts)
    for (const std::string& v : kValues) {
      const auto args = split_cmd(o.prefix + " " + o.option + " " + v);
      fs::remove_all(out);
      // A 1e9 m strip of --resolution 2 quads is a small mesh: sim may run it (without --resolution
      // the quad count refuses it); every other size here is refused.
      const bool must = must_refuse(o.kind, v) && !(o.runs && o.kind == Size && v == "1e9,1e9");
      const Run r = run(args, 60);
      std::vector<std::string> names = {o.option};
      // strip checks --size against the pattern's yarn once it has the pattern: the missing one first.
      if (o.prefix.find(missing) != std::string::npos) names.push_back(missing);
      if (!must) names.push_back(o.runs ? out : (o.prefix.find(missing) != std::string::npos ? missing : under_file));
      if (!must && o.prefix.find("export-hylc") != std::string::npos) names.push_back(B);
      if (!must && o.prefix.find("fit-splines") != std::string::npos) names.push_back(D);
      judge(args, r, must, names, t1, o.runs && r.status == 0 && nonfinite_in(out));
    }
  // Random --strip-args and --sim-args (accuracy and study check them before any stage).
  const std::vector<std::string> strip_opts = {"--clamp", "--tolerance", "--newton", "--max-iterations", "--bogus", "--connector-scale", "--size"};
  const std::vector<std::string> sim_opts = {"--dt", "--tol", "--integrator", "--friction", "--clamp", "--resolution", "--bogus", "--air"};
  for (int i = 0; i < 30; ++i) {
    const bool s = i % 2 == 0;
    const auto& list = s ? strip_opts : sim_opts;
    const std::string o = list[pick(rng, int(list.size()))];
    std::string v = kValues[pick(rng, 11)];  // nan .. 2147483648
    if (v == "''") v = "nan";
    const std::string head = i % 3 == 0 ? "study table5 " + pat + " -o " + under_file : acc;
    const auto args = split_cmd(head + (s ? " --strip-args '" : " --sim-args '") + o + " " + v + "'");
    judge(args, run(args, 60), true, {o, under_file}, t1);
  }
  // The issue's command lines (items 5 and 6).
  for (const std::string& line :
       {"strip " + missing + " --size 1e9,1e9 -o " + out, "strip stockinette --size 1e9,1e9 -o " + out,
        acc + "--size 0,0.1", acc + "--strip-args '--bogus'", acc + "--sim-args '--dt -1'", acc + "--baked " + D,
        acc + "--stretch 1.0:0.5:0.05", "accuracy " + missing + " --direction wale -o " + out,
        "study table5 " + pat + " -o " + out + " --size 0,0", "sim stretch --size 1e9,1e9 -o " + out + " --material " + B,
        "sim drape -o " + out + " --material " + B + " --dt nan", "export-hylc " + B + " --density nan -o " + p("m.json"),
        "export-hylc " + B + " --margin nan -o " + p("m.json"), "export-hylc " + B + " --margin 1e-300 -o " + p("m.json"),
        // item 10: a small strip of a pattern whose rest yarn is straight ran 45 s to exit 2
        "strip " + opt.strip_pattern + " --size 0.01,0.02 --stretch 1.0:1.05:0.05 -o " + out}) {
    const auto args = split_cmd(line);
    judge(args, run(args, 60), true, {}, t1);
  }
  t1.print("E1. result");
  all.add(t1);

  // E2. Scene-file mutants through sim (one frame at most, 60 s limit); the issue's scenes first.
  Tally t2;
  std::printf("\nE2. %d scene-file mutants through `sim SCENE --frames 1`\n", opt.scene_mutants);
  const std::vector<std::string> corpus = {
      R"({"mesh": {"rectangle": {"width": 1, "height": 1, "nx": 100000000, "ny": 100000000}}, "areal_density": 0.3})",
      R"({"mesh": {"rectangle": {"width": 1e999, "height": 1, "nx": 2, "ny": 2}}, "areal_density": 0.3})",
      std::string(100000, '[') + std::string(100000, ']'),
      R"({"mesh": {"rectangle": {"width": 0.1, "height": 0.1, "nx": 2, "ny": 2}}, "areal_density": 0.3, "stretch_report": {"handle": 0, "axis": [0, 0, 0], "length": 0.1, "width": 0.1, "middle": [0, 0]}, "handles": [{"select": {"vertices": [0]}, "path": [[0, 0, 0, 0], [1, 0.01, 0, 0]]}]})",
      R"({"mesh": {"obj": "."}, "areal_density": 0.3})", R"({"mesh": {"obj": "/dev/zero"}, "areal_density": 0.3})"};
  for (int i = 0; i < opt.scene_mutants; ++i) {
    const std::string f = p("scene" + std::to_string(i) + ".json");
    std::ofstream(f, std::ios::binary) << (i < int(corpus.size()) ? corpus[i] : mutate_json(kScene, rng));
    fs::remove_all(out);
    const auto args = cmd({"sim", f, "-q", "--frames", "1", "--render", "none", "--threads", "1", "--material", B, "-o", out});
    const Run r = run(args, 60);
    judge(args, r, i < 5, {f}, t2, r.status == 0 && nonfinite_in(out));
  }
  {  // a scene that is a folder
    fs::create_directories(p("scene_dir.json"));
    const auto args = cmd({"sim", p("scene_dir.json"), "--material", B, "-o", out});
    judge(args, run(args, 60), true, {p("scene_dir.json")}, t2);
  }
  t2.print("E2. result");
  all.add(t2);

  // E3. HYLC material mutants through sim drape (one frame of a 2 x 2 sheet).
  Tally t3;
  std::printf("\nE3. %d HYLC material JSON mutants through `sim drape --material M.json`\n", opt.hylc_mutants);
  const std::string hylc = slurp(p("hylc.json"));
  for (int i = 0; i < opt.hylc_mutants; ++i) {
    const std::string f = p("hylc" + std::to_string(i) + ".json");
    std::ofstream(f, std::ios::binary) << mutate_json(hylc, rng);
    fs::remove_all(out);
    const auto args = cmd({"sim", "drape", "-q", "--frames", "1", "--resolution", "2", "--render", "none", "--no-frames",
                           "--threads", "1", "--material", f, "-o", out});
    const Run r = run(args, 60);
    judge(args, r, false, {f}, t3, r.status == 0 && nonfinite_in(out));
  }
  t3.print("E3. result");
  all.add(t3);

  // E4. FIFOs as inputs: each refused by name, never waited on.
  Tally t4;
  std::printf("\nE4. FIFOs named as inputs\n");
  ::mkfifo(p("fifo").c_str(), 0644);
  const std::string F = p("fifo");
  std::ofstream(p("scene_mat.json")) << R"({"mesh": {"rectangle": {"width": 0.1, "height": 0.1, "nx": 2, "ny": 2}}, "areal_density": 0.3, "material": ")" + F + "\"}";
  std::ofstream(p("scene_obj.json")) << R"({"mesh": {"obj": ")" + F + R"("}, "areal_density": 0.3})";
  for (const std::vector<std::string>& a : std::vector<std::vector<std::string>>{
           cmd({"sim", F, "--material", B, "-o", out}), cmd({"sim", "drape", "--material", F, "-o", out}),
           cmd({"sim", p("scene_mat.json"), "-o", out}), cmd({"sim", p("scene_obj.json"), "--material", B, "-o", out}),
           cmd({"export-hylc", F, "--density", "0.3", "-o", p("m.json")}), cmd({"fit-splines", F, "-o", p("s.h5")}),
           cmd({"strip", F, "-o", out}), cmd({"strip", pat, "--material", F, "-o", out}),
           cmd({"accuracy", pat, "--direction", "wale", "--dataset", F, "-o", out}),
           cmd({"accuracy", pat, "--direction", "wale", "--baked", F, "-o", out}),
           cmd({"eval", F, "--term", "0", "--at", "0.1"}), cmd({"bake", F, "-o", p("x.h5")})})
    judge(a, run(a, 60), true, {F}, t4);
  t4.print("E4. result");
  all.add(t4);

  // E5. One corrupted byte of a baked file's first 4 KiB through eval, 1D and 2D terms.
  Tally t5;
  std::printf("\nE5. %d baked files with one corrupted byte through eval\n", opt.baked_mutants);
  const std::string baked = slurp(B);
  for (int i = 0; i < opt.baked_mutants; ++i) {
    std::string t = baked;
    const size_t at = size_t(pick(rng, int(std::min<size_t>(t.size(), 4096))));
    t[at] = char(t[at] ^ (1 + pick(rng, 255)));
    const std::string f = p("baked" + std::to_string(i) + ".h5");
    std::ofstream(f, std::ios::binary) << t;
    const auto args = i % 2 ? cmd({"eval", f, "--term", "0", "--at", "0.1"}) : cmd({"eval", f, "--term", "02", "--at", "0.1,0.1"});
    const Run r = run(args, 60);
    const bool bad = r.status == 0 && (r.out.find("nan") != std::string::npos || r.out.find("inf") != std::string::npos);
    judge(args, r, false, {f}, t5, bad);
    fs::remove(f);
  }
  t5.print("E5. result");
  all.add(t5);
  all.print("\nE. result");
  std::printf("\n");
}

}  // namespace campaign
