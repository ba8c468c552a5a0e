#include "pipeline/accuracy_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "accuracy/box_reach.hpp"
#include "core/baked.hpp"
#include "core/dataset.hpp"
#include "core/file_checks.hpp"
#include "core/number_list.hpp"
#include "core/text_file.hpp"
#include "io/csv_columns.hpp"
#include "pipeline/rank_tasks.hpp"
#include "pipeline/stage_runner.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

std::vector<std::string> produce_stage_args(const std::string& pattern, const std::string& dataset,
                                            const std::string& preset, int threads) {
  std::vector<std::string> a = {"produce", pattern, "-o", dataset, "--preset", preset};
  add_count_option(a, "--threads", threads);
  return a;
}

std::vector<std::string> train_stage_args(const std::string& dataset, const std::string& model, int threads, int epochs) {
  std::vector<std::string> a = {"train-all", dataset, "-o", model, "-q"};
  add_count_option(a, "--threads", threads);
  add_count_option(a, "--epochs", epochs);
  return a;
}

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

// The test's stages, run in order (or as tasks on ranks, add_accuracy_tasks); the seconds of
// those that ran go to r.stage_seconds.
class AccuracyStages {
 public:
  AccuracyStages(const AccuracyOptions& o, AccuracyResult& r)
      : o_(o), r_(r), dir_(o.out), mdir_(o.materials_dir.empty() ? dir_ : fs::path(o.materials_dir)),
        strip_dir_(o.strip_dir.empty() ? dir_ / "strip" : fs::path(o.strip_dir)) {
    if (fs::exists(o.pattern)) pattern_in_.push_back(o.pattern);
  }

  const fs::path& strip_dir() const { return strip_dir_; }
  std::string dataset() const { return o_.dataset.empty() ? (mdir_ / "dataset.h5").string() : o_.dataset; }
  std::string neural() const { return o_.baked.empty() ? (mdir_ / "neural.h5").string() : o_.baked; }
  std::string spline() const { return (mdir_ / "spline.h5").string(); }
  // A stage's record: what names it among the tasks of a study.
  std::string record(const std::string& stage) const {
    const fs::path d = stage == "strip" ? strip_dir_.parent_path() : stage.rfind("sim-", 0) == 0 ? dir_ : mdir_;
    return (d / ".stages" / (stage == "strip" ? strip_name() : stage)).string();
  }

  // The dataset, the neural material and the spline baseline. Stages that make materials keep
  // their records beside them, so that several tests share them.
  void materials() {
    produce();
    train_and_bake();
    r_.materials.push_back({"neural", neural(), {}, {}, {}, {}});
    if (o_.spline) {
      fit_splines();
      r_.materials.push_back({"spline", spline(), {}, {}, {}, {}});
    }
  }
  void produce() {
    fs::create_directories(mdir_);
    if (o_.dataset.empty())
      stage(mdir_, {"produce", produce_stage_args(o_.pattern, dataset(), o_.preset, o_.threads), pattern_in_, {dataset()}});
  }
  void train_and_bake() {
    if (!o_.baked.empty()) return;
    fs::create_directories(mdir_);
    const std::string ds = dataset(), model = (mdir_ / "model.h5").string();
    stage(mdir_, {"train-all", train_stage_args(ds, model, o_.threads, o_.epochs), {ds}, {model}});
    stage(mdir_, {"bake", {"bake", model, "-o", neural(), "--data", ds}, {model, ds}, {neural()}});
  }
  void fit_splines() {
    fs::create_directories(mdir_);
    stage(mdir_, {"fit-splines", {"fit-splines", dataset(), "-o", spline()}, {dataset()}, {spline()}});
  }

  // The yarn strip; its record lives beside the strip, so that tests sharing it run it once.
  void strip() {
    std::vector<std::string> a = {"strip", o_.pattern, "--size", o_.size, "--direction", o_.direction,
                                  "--stretch", o_.stretch, "-o", strip_dir_.string()};
    for (const auto& x : split_spaces(o_.strip_args)) a.push_back(x);
    const StageSpec s = {strip_name(), a, pattern_in_, {(strip_dir_ / "force.csv").string()}};
    const StageOutcome out = run_stage(strip_dir_.parent_path(), s, o_.force);
    if (out.ran) r_.stage_seconds.emplace_back("strip", out.seconds);
  }

  // sim stretch: a continuum strip of the yarn strip's size and clamp bands (its settings.txt
  // says which band it used), stretched through the same ratios.
  void continuum_strips() {
    const std::vector<double> ratios = parse_stretch_range(o_.stretch);
    if (ratios.size() < 2 || std::abs(ratios.front() - 1.0) > 1e-9)
      throw std::invalid_argument("--stretch " + o_.stretch + ": the test starts at the relaxed 100 %; give 1.0:LAST:STEP");
    for (MaterialResult& m : r_.materials) m.failure = sim(m.name, m.baked);
  }
  // One material's continuum strip; "" or why the baseline's stopped. The neural material is
  // what is tested: its failure fails the command. The baseline's is a result (HYLC-style linear
  // extrapolation can fall outward and run away): recorded, and its metrics cover the tests its
  // strip reached.
  std::string sim(const std::string& name, const std::string& baked) {
    std::string clamp = "0.005";
    {
      std::ifstream st(strip_dir_ / "settings.txt");
      for (std::string line; std::getline(st, line);)
        if (line.rfind("clamp = ", 0) == 0) clamp = line.substr(8);
    }
    const fs::path sd = dir_ / ("sim_" + name);
    std::vector<std::string> a = {"sim", "stretch", "-o", sd.string(), "--material", baked, "--direction", o_.direction,
                                  "--size", o_.size, "--stretch", o_.stretch, "--clamp", clamp, "-q"};
    for (const auto& x : split_spaces(o_.sim_args)) a.push_back(x);
    // A baseline's stop is remembered for the rest of this run (rank 0's single pass after the
    // ranks' tasks does not run it again); a later run tries again.
    const std::string stopped = (dir_ / ".stages" / ("sim-" + name + ".stopped")).string(), id = stage_run_id() + "\n";
    std::string why;
    if (name != "neural") {
      std::ifstream in(stopped);
      std::getline(in, why, '\0');
      why = why.rfind(id, 0) == 0 ? why.substr(id.size()) : "";
    }
    try {
      if (why.empty()) stage(dir_, {"sim-" + name, a, {baked}, {(sd / "stretch.csv").string()}});
    } catch (const std::runtime_error& e) {
      if (name == "neural") throw;
      why = e.what();
      write_text_file(stopped, id + why);
    }
    if (!why.empty())
      std::fprintf(stderr, "yarnhom accuracy: the %s baseline's continuum strip stopped early; its metrics cover the tests it "
                   "reached\n", name.c_str());
    return why;
  }

 private:
  std::string strip_name() const { return "strip-" + strip_dir_.filename().string(); }
  void stage(const fs::path& dir, const StageSpec& s) {
    const StageOutcome out = run_stage(dir, s, o_.force);
    if (out.ran) r_.stage_seconds.emplace_back(s.name, out.seconds);
  }

  const AccuracyOptions& o_;
  AccuracyResult& r_;
  const fs::path dir_, mdir_, strip_dir_;
  std::vector<std::string> pattern_in_;
};

// Metrics: step by step, the same stretch ratios in both force curves.
void measure(const AccuracyOptions& o, const fs::path& strip_dir, AccuracyResult& r) {
  const fs::path dir(o.out);
  std::vector<double> ys, yt;
  r.n_yarn_per_load_width = read_force((strip_dir / "force.csv").string(), ys, yt);
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
}

// ",%.6g" of a value, or "," where there is none.
std::string cell(const double* v) {
  if (!v) return ",";
  char buf[40];
  std::snprintf(buf, sizeof buf, ",%.6g", *v);
  return buf;
}

// accuracy.csv: one row per stretch ratio; a material whose strip stopped before a test has
// empty cells there.
std::string accuracy_csv(const AccuracyResult& r) {
  std::string f = "stretch,N_yarn";
  for (const auto& m : r.materials)
    f += ",N_" + m.name + ",dN_" + m.name + ",hausdorff_cm_" + m.name + ",hausdorff_points_cm_" + m.name +
         ",hausdorff_surface_cm_" + m.name;
  // Each strip's projected width at its middle (accuracy/middle_width.hpp).
  f += ",middle_width_mm_yarn";
  for (const auto& m : r.materials) f += ",middle_width_mm_" + m.name;
  // The same two measures of the fabric's own yarn, the soft boundary yarn left out
  // (StepMetrics::hausdorff_fabric); last, so that the columns before keep their places.
  f += ",middle_width_fabric_mm_yarn";
  for (const auto& m : r.materials) f += ",hausdorff_fabric_cm_" + m.name;
  f += "\n";
  char buf[160];
  for (size_t k = 0; k < r.stretch.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.4f,%.6g", r.stretch[k], r.n_yarn[k]);
    f += buf;
    const StepMetrics* any = nullptr;
    for (const auto& m : r.materials) {
      if (k >= m.steps.size()) {
        f += ",,,,,";
        continue;
      }
      const StepMetrics& s = m.steps[k];
      any = &s;
      const double v[5] = {s.n_cont, s.stress_diff, 100 * s.hausdorff.symmetric, 100 * s.hausdorff.points_to_surface,
                           100 * s.hausdorff.surface_to_points};
      for (const double& x : v) f += cell(&x);
    }
    // Per material a value of its step k, or an empty cell.
    auto per_material = [&](double (*value)(const StepMetrics&)) {
      for (const auto& m : r.materials) {
        const double v = k < m.steps.size() ? value(m.steps[k]) : 0;
        f += cell(k < m.steps.size() ? &v : nullptr);
      }
    };
    const double wy = any ? 1e3 * any->width_yarn : 0, wf = any ? 1e3 * any->width_yarn_fabric : 0;
    f += cell(any ? &wy : nullptr);
    per_material([](const StepMetrics& s) { return 1e3 * s.width_cont; });
    f += cell(any ? &wf : nullptr);
    per_material([](const StepMetrics& s) { return 100 * s.hausdorff_fabric.symmetric; });
    f += "\n";
  }
  return f;
}

}  // namespace

void check_accuracy_options(const AccuracyOptions& o) {
  const std::vector<double> ratios = parse_stretch_range(o.stretch);
  if (ratios.size() < 2 || std::abs(ratios.front() - 1.0) > 1e-9)
    throw std::invalid_argument("--stretch " + o.stretch + ": the test starts at the relaxed 100 %; give 1.0:LAST:STEP");
  if (!o.baked.empty()) {
    if (!is_baked_file(o.baked))
      throw std::invalid_argument("--baked " + o.baked + ": not a yarnhom baked file (yarnhom bake writes one; a dataset "
                                  "goes to --dataset)");
    read_baked(o.baked);
  }
  if (!o.dataset.empty()) {
    if (is_baked_file(o.dataset)) throw std::invalid_argument("--dataset " + o.dataset + ": a baked file, not a dataset (give it as --baked)");
    read_dataset(o.dataset);
  }
}

AccuracyResult run_accuracy(const AccuracyOptions& o, std::chrono::steady_clock::time_point t0) {
  fs::create_directories(o.out);
  AccuracyResult r;
  AccuracyStages stages(o, r);
  stages.materials();
  stages.strip();
  stages.continuum_strips();
  measure(o, stages.strip_dir(), r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_text_file((fs::path(o.out) / "accuracy.csv").string(), accuracy_csv(r));
  write_text_file((fs::path(o.out) / "accuracy.md").string(), accuracy_report_text(r, o));
  return r;
}

double produce_task_weight(const std::string& preset, int tiles) {
  // An n x n patch's solves cost 13-27x one tile's at n = 2 (docs/produce.md).
  return 100 * (preset == "paper" ? 1.0 : preset == "quick" ? 0.1 : 0.01) * (tiles > 1 ? 5.0 * tiles * tiles : 1.0);
}

namespace {

double strip_weight(const AccuracyOptions& o) {
  double w = 0.05, l = 0.10;
  if (std::sscanf(o.size.c_str(), "%lf,%lf", &w, &l) != 2) w = 0.05, l = 0.10;
  const double steps = double(parse_stretch_range(o.stretch).size());
  return std::max(0.1, w * l / 0.005) * steps / 15;
}

}  // namespace

void add_accuracy_tasks(RankTasks& g, const AccuracyOptions& o, const std::string& label, const std::vector<int>& after) {
  AccuracyResult none;
  const AccuracyStages s(o, none);
  // Each task makes its own stages object from its copy of the options.
  auto task = [o](void (*piece)(AccuracyStages&)) {
    return [o, piece] {
      AccuracyResult r;
      AccuracyStages st(o, r);
      piece(st);
    };
  };
  const double steps = double(parse_stretch_range(o.stretch).size()) / 15;
  const int strip = g.add(s.record("strip"), label + ": yarn strip " + o.size + " m", 40 * strip_weight(o), {},
                          task([](AccuracyStages& st) { st.strip(); }));
  std::vector<int> before = after;
  if (o.dataset.empty())
    before.push_back(g.add(s.record("produce"), label + ": produce (" + o.preset + ")", produce_task_weight(o.preset), after,
                           task([](AccuracyStages& st) { st.produce(); })));
  std::vector<int> neural = before, spline = before;
  if (o.baked.empty())
    neural.push_back(g.add(s.record("train-all"), label + ": train-all, bake", 10, before,
                           task([](AccuracyStages& st) { st.train_and_bake(); })));
  neural.push_back(strip);
  g.add(s.record("sim-neural"), label + ": sim stretch, neural", 3 * steps, neural,
        task([](AccuracyStages& st) { st.sim("neural", st.neural()); }));
  if (!o.spline) return;
  spline.push_back(g.add(s.record("fit-splines"), label + ": fit-splines", 1, before,
                         task([](AccuracyStages& st) { st.fit_splines(); })));
  spline.push_back(strip);
  g.add(s.record("sim-spline"), label + ": sim stretch, spline", 3 * steps, spline,
        task([](AccuracyStages& st) { st.sim("spline", st.spline()); }));
}

void run_accuracy_command(const AccuracyOptions& o, const std::vector<std::string>& commands) {
  check_output_folder(o.out);
  for (const char* need : {"produce", "strip", "sim"}) {
    if (std::string(need) == "produce" && !o.dataset.empty()) continue;
    if (std::find(commands.begin(), commands.end(), need) == commands.end())
      throw std::invalid_argument(std::string("this build has no '") + need +
                                  "' command, which the accuracy test needs (docs/accuracy.md)");
  }
  // On several ranks (pipeline/rank_tasks.hpp): the yarn strip, the materials and the continuum
  // strips as tasks, then rank 0 alone measures and writes.
  const auto t0 = std::chrono::steady_clock::now();
  const OnRanks ranks(o.out, "accuracy", [&](RankTasks& g) { add_accuracy_tasks(g, o, fs::path(o.pattern).stem().string() + ", " + o.direction);
  });
  if (!ranks.root()) return;
  const AccuracyResult r = run_accuracy(o, t0);
  std::printf("%s", accuracy_report_text(r, o).c_str());
}

}  // namespace yarnhom::pipeline
