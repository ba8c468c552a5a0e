// yarnhom accuracy: one pattern, one direction, end to end (supplement section 4.2, Table 5):
// dataset -> networks -> baked material, the spline baseline on the same data, the yarn-level
// strip and the continuum strip for both materials under the same clamps, and per stretch the
// stress difference and the Hausdorff distance (docs/accuracy.md says exactly what).
//
// Every stage is a subcommand of this program run as a child process with its log, cached and
// resumable like `pipeline` (tools/stage_runner.hpp); the metrics are computed here.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "accuracy/box_reach.hpp"
#include "accuracy/csv_columns.hpp"
#include "core/atomic_file.hpp"
#include "tools/accuracy_run.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"
#include "tools/stage_runner.hpp"

namespace yarnhom::tools {

namespace fs = std::filesystem;

namespace {

std::vector<std::string> split_spaces(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == ' ') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

// The per-step OBJ files in a stage's output folder, in name order (the commands number their
// steps with zero padding): exactly `n` are expected, or at least `n` (the first n) for a run that
// stopped early.
std::vector<std::string> step_objs(const fs::path& folder, size_t n, bool at_least = false) {
  std::vector<std::string> files;
  if (fs::is_directory(folder))
    for (const auto& e : fs::recursive_directory_iterator(folder))
      if (e.is_regular_file() && e.path().extension() == ".obj") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  if (files.size() != n && !(at_least && files.size() > n))
    throw std::runtime_error(folder.string() + ": found " + std::to_string(files.size()) + " OBJ files, expected one per stretch step (" +
                             std::to_string(n) + ")");
  files.resize(n);
  return files;
}

// stretch and tension (N/m) columns of a force curve. A yarn strip's force is taken per its load
// width (the width of fabric its rows stand for, yarn::Strip::load_width) where force.csv has it;
// strips written before it was recorded give the force per nominal width.
// Returns whether the force is per load width.
bool read_force(const std::string& path, std::vector<double>& stretch, std::vector<double>& tension) {
  const std::vector<std::string> names = {"tension_load_N_per_m", "tension_N_per_m", "force_per_width_N_per_m"};
  std::vector<std::string> only = {"stretch", "ratio", "lambda"};
  only.insert(only.end(), names.begin(), names.end());
  const CsvColumns t = read_csv_columns(path, only);
  stretch = csv_column(t, {"stretch", "ratio", "lambda"}, path);
  tension = csv_column(t, names, path);
  return t.count("tension_load_N_per_m") > 0;
}

}  // namespace

AccuracyResult run_accuracy(const AccuracyOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path dir(o.out);
  fs::create_directories(dir);
  AccuracyResult r;
  auto stage = [&](const StageSpec& s) {
    const StageOutcome out = run_stage(dir, s, o.force);
    if (out.ran) r.stage_seconds.emplace_back(s.name, out.seconds);
  };
  std::vector<std::string> pattern_in;
  if (fs::exists(o.pattern)) pattern_in.push_back(o.pattern);
  const fs::path mdir = o.materials_dir.empty() ? dir : fs::path(o.materials_dir);
  fs::create_directories(mdir);
  // Stages that make materials keep their records beside them, so that several tests share them.
  auto mstage = [&](const StageSpec& s) {
    const StageOutcome out = run_stage(mdir, s, o.force);
    if (out.ran) r.stage_seconds.emplace_back(s.name, out.seconds);
  };
  const std::string ds = o.dataset.empty() ? (mdir / "dataset.h5").string() : o.dataset;
  if (o.dataset.empty()) {
    std::vector<std::string> a = {"produce", o.pattern, "-o", ds, "--preset", o.preset};
    if (o.threads > 0) { a.push_back("--threads"); a.push_back(std::to_string(o.threads)); }
    mstage({"produce", a, pattern_in, {ds}});
  }
  std::string neural = o.baked;
  if (neural.empty()) {
    const std::string model = (mdir / "model.h5").string();
    neural = (mdir / "neural.h5").string();
    std::vector<std::string> a = {"train-all", ds, "-o", model, "-q"};
    if (o.threads > 0) { a.push_back("--threads"); a.push_back(std::to_string(o.threads)); }
    if (o.epochs > 0) { a.push_back("--epochs"); a.push_back(std::to_string(o.epochs)); }
    mstage({"train-all", a, {ds}, {model}});
    mstage({"bake", {"bake", model, "-o", neural, "--data", ds}, {model, ds}, {neural}});
  }
  r.materials.push_back({"neural", neural, {}, {}, {}, {}});
  if (o.spline) {
    const std::string spline = (mdir / "spline.h5").string();
    mstage({"fit-splines", {"fit-splines", ds, "-o", spline}, {ds}, {spline}});
    r.materials.push_back({"spline", spline, {}, {}, {}, {}});
  }
  const fs::path strip_dir = o.strip_dir.empty() ? dir / "strip" : fs::path(o.strip_dir);
  const std::string strip_force = (strip_dir / "force.csv").string();
  {
    std::vector<std::string> a = {"strip", o.pattern, "--size", o.size, "--direction", o.direction,
                                  "--stretch", o.stretch, "-o", strip_dir.string()};
    for (const auto& x : split_spaces(o.strip_args)) a.push_back(x);
    // The strip's record lives beside the strip, so that tests sharing it run it once.
    const StageOutcome out = run_stage(strip_dir.parent_path(), {"strip-" + strip_dir.filename().string(), a, pattern_in, {strip_force}}, o.force);
    if (out.ran) r.stage_seconds.emplace_back("strip", out.seconds);
  }
  // sim stretch: a continuum strip of the yarn strip's size and clamp bands (its settings.txt
  // says which band it used), stretched through the same ratios.
  std::string clamp = "0.005";
  {
    std::ifstream st(strip_dir / "settings.txt");
    for (std::string line; std::getline(st, line);)
      if (line.rfind("clamp = ", 0) == 0) clamp = line.substr(8);
  }
  const std::vector<double> ratios = parse_stretch_range(o.stretch);
  if (ratios.size() < 2 || std::abs(ratios.front() - 1.0) > 1e-9)
    throw std::invalid_argument("--stretch " + o.stretch + ": the test starts at the relaxed 100 %; give 1.0:LAST:STEP");
  for (MaterialResult& m : r.materials) {
    const fs::path sd = dir / ("sim_" + m.name);
    std::vector<std::string> a = {"sim", "stretch", "-o", sd.string(), "--material", m.baked, "--direction", o.direction,
                                  "--size", o.size, "--stretch", o.stretch, "--clamp", clamp, "-q"};
    for (const auto& x : split_spaces(o.sim_args)) a.push_back(x);
    // The neural material is what is tested: its failure fails the command. The baseline's is a
    // result (HYLC-style linear extrapolation can fall outward and run away): recorded, and its
    // metrics cover the tests its strip reached.
    try {
      stage({"sim-" + m.name, a, {m.baked}, {(sd / "stretch.csv").string()}});
    } catch (const std::runtime_error& e) {
      if (m.name == "neural") throw;
      m.failure = e.what();
      std::fprintf(stderr, "yarnhom accuracy: the %s baseline's continuum strip stopped early; its metrics cover the tests it "
                   "reached\n", m.name.c_str());
    }
  }

  // Metrics: step by step, the same stretch ratios in both force curves.
  std::vector<double> ys, yt;
  r.n_yarn_per_load_width = read_force(strip_force, ys, yt);
  r.stretch = ys;
  r.n_yarn = yt;
  const auto yarn_objs = step_objs(strip_dir / "centrelines", ys.size());
  for (MaterialResult& m : r.materials) {
    const fs::path sd = dir / ("sim_" + m.name);
    std::vector<double> cs, ct;
    const bool failed = !m.failure.empty();
    if (!failed || fs::exists(sd / "stretch.csv")) read_force((sd / "stretch.csv").string(), cs, ct);
    if (cs.size() != ys.size() && !(failed && cs.size() < ys.size()))
      throw std::runtime_error((sd / "stretch.csv").string() + ": " + std::to_string(cs.size()) + " steps, the yarn strip has " +
                               std::to_string(ys.size()));
    // sim writes frame k >= 1 after step k; the first row (100 %) is the undeformed strip, frame 0.
    const auto objs = step_objs(sd / "frames", cs.size(), failed);
    for (size_t k = 0; k < cs.size(); ++k) {
      if (std::abs(cs[k] - ys[k]) > 1e-6)
        throw std::runtime_error("step " + std::to_string(k) + ": stretch " + std::to_string(cs[k]) + " in " + sd.string() +
                                 " but " + std::to_string(ys[k]) + " in the yarn strip");
      m.steps.push_back(compare_step(yarn_objs[k], objs[k], ys[k], yt[k], ct[k], o.spacing));
    }
    m.summary = summarize(m.steps);
    // Where the strip's middle left the data (stretch.csv of older runs has no middle columns).
    if (fs::exists(sd / "stretch.csv")) {
      const CsvColumns mc = read_csv_columns((sd / "stretch.csv").string(), {"middle_s_x", "middle_s_a", "middle_s_y"});
      std::vector<std::vector<double>> mid(3);
      const char* names[3] = {"middle_s_x", "middle_s_a", "middle_s_y"};
      for (int c = 0; c < 3; ++c)
        if (mc.count(names[c])) mid[c] = mc.at(names[c]);
      m.box_note = box_reach_text(box_reach(read_baked(m.baked), mid), ys);
    }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // accuracy.csv: one row per stretch ratio.
  {
    AtomicOutput out((dir / "accuracy.csv").string());
    {
      std::ofstream f(out.temp_path());
      f << "stretch,N_yarn";
      for (const auto& m : r.materials)
        f << ",N_" << m.name << ",dN_" << m.name << ",hausdorff_cm_" << m.name << ",hausdorff_points_cm_" << m.name
          << ",hausdorff_surface_cm_" << m.name;
      // Each strip's projected width at its middle (accuracy/middle_width.hpp).
      f << ",middle_width_mm_yarn";
      for (const auto& m : r.materials) f << ",middle_width_mm_" << m.name;
      // The same two measures of the fabric's own yarn, the soft boundary yarn left out
      // (StepMetrics::hausdorff_fabric); last, so that the columns before keep their places.
      f << ",middle_width_fabric_mm_yarn";
      for (const auto& m : r.materials) f << ",hausdorff_fabric_cm_" << m.name;
      f << "\n";
      char buf[160];
      for (size_t k = 0; k < r.stretch.size(); ++k) {
        std::snprintf(buf, sizeof buf, "%.4f,%.6g", r.stretch[k], r.n_yarn[k]);
        f << buf;
        for (const auto& m : r.materials) {
          if (k >= m.steps.size()) {  // a baseline that stopped before this test: empty cells
            f << ",,,,,";
            continue;
          }
          const StepMetrics& s = m.steps[k];
          std::snprintf(buf, sizeof buf, ",%.6g,%.6g,%.6g,%.6g,%.6g", s.n_cont, s.stress_diff, 100 * s.hausdorff.symmetric,
                        100 * s.hausdorff.points_to_surface, 100 * s.hausdorff.surface_to_points);
          f << buf;
        }
        const StepMetrics* any = nullptr;
        for (const auto& m : r.materials)
          if (k < m.steps.size()) any = &m.steps[k];
        if (any) {
          std::snprintf(buf, sizeof buf, ",%.6g", 1e3 * any->width_yarn);
          f << buf;
        } else {
          f << ",";
        }
        for (const auto& m : r.materials) {
          if (k >= m.steps.size()) {
            f << ",";
            continue;
          }
          std::snprintf(buf, sizeof buf, ",%.6g", 1e3 * m.steps[k].width_cont);
          f << buf;
        }
        if (any) {
          std::snprintf(buf, sizeof buf, ",%.6g", 1e3 * any->width_yarn_fabric);
          f << buf;
        } else {
          f << ",";
        }
        for (const auto& m : r.materials) {
          if (k >= m.steps.size()) {
            f << ",";
            continue;
          }
          std::snprintf(buf, sizeof buf, ",%.6g", 100 * m.steps[k].hausdorff_fabric.symmetric);
          f << buf;
        }
        f << "\n";
      }
    }
    out.commit();
  }
  {
    AtomicOutput out((dir / "accuracy.md").string());
    {
      std::ofstream f(out.temp_path());
      f << accuracy_report_text(r, o);
    }
    out.commit();
  }
  return r;
}

std::string accuracy_report_text(const AccuracyResult& r, const AccuracyOptions& o) {
  std::string s;
  char buf[256];
  std::snprintf(buf, sizeof buf, "\naccuracy %s, %s, strip %s m, stretch %s (%zu tests)\n\n", o.pattern.c_str(),
                o.direction.c_str(), o.size.c_str(), o.stretch.c_str(), r.stretch.size());
  s += buf;
  s += "| stretch | N_yarn (N/m) |";
  for (const auto& m : r.materials) s += " " + m.name + ": dN (N/m), H (cm) |";
  s += "\n|---|---|";
  for (size_t k = 0; k < r.materials.size(); ++k) s += "---|";
  s += "\n";
  for (size_t k = 0; k < r.stretch.size(); ++k) {
    std::snprintf(buf, sizeof buf, "| %.0f %% | %.3f |", 100 * r.stretch[k], r.n_yarn[k]);
    s += buf;
    for (const auto& m : r.materials) {
      if (k >= m.steps.size()) {
        s += " stopped |";
        continue;
      }
      std::snprintf(buf, sizeof buf, " %.3f, %.3f |", m.steps[k].stress_diff, 100 * m.steps[k].hausdorff.symmetric);
      s += buf;
    }
    s += "\n";
  }
  s += "\nmeans over the tests: stress difference (N/m), Hausdorff (cm), mean relative stress error (tests with "
       "|N_yarn| >= 1 % of its largest), ratio of means\n";
  for (const auto& m : r.materials) {
    const AccuracySummary& a = m.summary;
    std::snprintf(buf, sizeof buf, "  %-7s %.3f N/m, %.3f cm, %.2f %% (%d tests), %.2f %%\n", m.name.c_str(), a.mean_stress_diff,
                  100 * a.mean_hausdorff, 100 * a.mean_rel_error, a.rel_tests, 100 * a.ratio_of_means);
    s += buf;
    if (!m.box_note.empty()) {
      std::string note = m.box_note;
      for (size_t at = 0; (at = note.find('\n', at)) != std::string::npos; at += 1) note.replace(at, 1, "\n  " + m.name + "  ");
      s += "  " + m.name + "  " + note + "\n";
    }
    if (!m.failure.empty()) {
      std::snprintf(buf, sizeof buf, "  %-7s STOPPED after %zu of %zu tests (the means above cover those): ", m.name.c_str(),
                    m.steps.size(), r.stretch.size());
      s += buf + m.failure + "\n";
    }
  }
  // Transverse contraction, measured alike on both strips (accuracy/middle_width.hpp).
  for (const auto& m : r.materials) {
    if (m.steps.size() < 2 || !(m.steps.front().width_yarn > 0) || !(m.steps.front().width_cont > 0)) continue;
    const StepMetrics &a = m.steps.front(), &b = m.steps.back();
    std::snprintf(buf, sizeof buf,
                  "  %-7s projected width at the middle, %.0f %% -> %.0f %%: yarn %.1f -> %.1f mm (%+.1f %%), continuum "
                  "%.1f -> %.1f mm (%+.1f %%)\n",
                  m.name.c_str(), 100 * a.stretch, 100 * b.stretch, 1e3 * a.width_yarn, 1e3 * b.width_yarn,
                  100 * (b.width_yarn / a.width_yarn - 1), 1e3 * a.width_cont, 1e3 * b.width_cont,
                  100 * (b.width_cont / a.width_cont - 1));
    s += buf;
  }
  // The fabric alone: where the boundary yarn's lanes set the distance, these say so.
  for (const auto& m : r.materials) {
    if (m.steps.empty()) continue;
    const AccuracySummary& a = m.summary;
    if (std::abs(a.mean_hausdorff_fabric - a.mean_hausdorff) < 1e-12 &&
        std::abs(m.steps.front().width_yarn_fabric - m.steps.front().width_yarn) < 1e-12)
      continue;  // no boundary yarn in the centrelines
    const StepMetrics &f = m.steps.front(), &b = m.steps.back();
    std::snprintf(buf, sizeof buf,
                  "  %-7s the fabric's yarn alone (boundary yarn left out): Hausdorff %.3f cm (mean), middle width "
                  "%.1f -> %.1f mm (%+.1f %%)\n",
                  m.name.c_str(), 100 * a.mean_hausdorff_fabric, 1e3 * f.width_yarn_fabric, 1e3 * b.width_yarn_fabric,
                  f.width_yarn_fabric > 0 ? 100 * (b.width_yarn_fabric / f.width_yarn_fabric - 1) : 0.0);
    s += buf;
  }
  if (!r.n_yarn_per_load_width)
    s += "  note: N_yarn is the yarn strip's force per its nominal width: its force.csv predates the load width "
         "(docs/strip.md section 3); rerun strip with the same settings (every step is kept) to record it\n";
  std::snprintf(buf, sizeof buf, "total %s\n", format_seconds(r.seconds).c_str());
  s += buf;
  return s;
}

void register_accuracy(CLI::App& app) {
  auto o = std::make_shared<AccuracyOptions>();
  CLI::App* root = &app;
  auto* cmd = app.add_subcommand(
      "accuracy",
      "The accuracy test of supplement section 4.2 for one pattern and direction: produce (or "
      "reuse) the dataset, train-all and bake (or reuse) the neural material, fit-splines (the "
      "HYLC-style baseline), the yarn-level strip (strip) and the continuum strip (sim stretch) "
      "for both materials with the same clamps; then per stretch ratio the stress difference "
      "(N/m) and the Hausdorff distance (cm) between the yarn centrelines and the continuum "
      "surface, and their means with the mean relative stress error. Writes OUT/accuracy.csv and "
      "OUT/accuracy.md. Every stage is cached and resumable (logs in OUT/logs).");
  cmd->add_option("PATTERN", o->pattern, "Pattern (.pyp file or built-in name), as produce and strip take it")->required();
  cmd->add_option("--direction", o->direction, "Stretch direction: course (x) or wale (y)")
      ->required()
      ->check(CLI::IsMember({"course", "wale"}));
  cmd->add_option("-o,--output", o->out, "Output folder (created)")->required();
  cmd->add_option("--preset", o->preset, "produce's sampling preset: quick or paper")
      ->check(CLI::IsMember({"quick", "paper"}))
      ->capture_default_str();
  cmd->add_option("--size", o->size, "Strip width,length in metres, the yarn strip's and the continuum strip's (the paper: 0.05,0.10)")->capture_default_str();
  cmd->add_option("--stretch", o->stretch, "Stretch ratios 1.0:LAST:STEP, both strips (the paper: 1.0:1.7:0.05, 15 tests)")
      ->capture_default_str();
  cmd->add_option("--dataset", o->dataset, "Reuse this dataset instead of producing one")->check(existing_regular_file());
  cmd->add_option("--baked", o->baked, "Reuse this baked neural material instead of training and baking")->check(existing_regular_file());
  cmd->add_option("--epochs", o->epochs, "train-all's epochs per network (0: its default)")
      ->check(CLI::Range(0, 100000000))
      ->capture_default_str();
  cmd->add_option("--threads", o->threads, "Threads for produce and train-all (0: all cores)")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  cmd->add_option("--spacing", o->spacing, "Surface sampling of the Hausdorff distance, metres")
      ->check(finite_positive())
      ->capture_default_str();
  cmd->add_option("--strip-args", o->strip_args, "Extra arguments for strip (one string, split at spaces)");
  cmd->add_option("--sim-args", o->sim_args, "Extra arguments for sim stretch (one string, split at spaces)");
  cmd->add_flag("--force", o->force, "Rerun every stage");
  cmd->callback([o, root] {
    check_output_folder(o->out);
    for (const char* need : {"produce", "strip", "sim"}) {
      if (std::string(need) == "produce" && !o->dataset.empty()) continue;
      bool have = false;
      for (CLI::App* sub : root->get_subcommands([](CLI::App*) { return true; })) have = have || sub->get_name() == need;
      if (!have)
        throw std::invalid_argument(std::string("this build has no '") + need +
                                    "' command, which the accuracy test needs (docs/accuracy.md)");
    }
    const AccuracyResult r = run_accuracy(*o);
    std::printf("%s", accuracy_report_text(r, *o).c_str());
  });
}

}  // namespace yarnhom::tools
