// yarnhom study table5 | bake-resolution | rve-size: the supplement's accuracy tables as
// commands (docs/accuracy.md); strip-width: how the yarn strip's force per width depends on its
// width, against the continuum strip of the same size. Each runs the accuracy test (tools/accuracy_run.hpp) for several
// patterns, directions or materials, cached and resumable stage by stage, and writes a Markdown
// and a CSV table beside the paper's figures.
//
// The `study` group is shared with other studies (train's `study architectures`): whichever
// registers first creates it.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <array>
#include <map>
#include <memory>

#include "core/atomic_file.hpp"
#include "tools/accuracy_run.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"
#include "tools/python_env.hpp"
#include "tools/stage_runner.hpp"
#include "yarn/pattern.hpp"

namespace yarnhom::tools {

namespace fs = std::filesystem;

namespace {

// Supplement Table 5, last column: mean stress difference (N/m), mean Hausdorff (cm), mean
// relative stress error (%); ours = the paper's neural model, hylc = [Sperl et al. 2020]. The
// HYLC row of cartridge (wale) is cut off in our copy of the supplement (NaN).
struct PaperRow {
  double ours[3], hylc[3];
};
const std::map<std::string, PaperRow>& paper_table5() {
  static const std::map<std::string, PaperRow> t = {
      {"basket/course", {{1.30, 0.63, 5.41}, {1.52, 0.63, 6.73}}},
      {"basket/wale", {{0.87, 0.69, 3.8}, {0.82, 0.70, 4.6}}},
      {"stockinette/course", {{1.94, 0.99, 7.3}, {2.26, 1.24, 14.9}}},
      {"stockinette/wale", {{3.04, 0.75, 13.7}, {3.83, 1.02, 20.1}}},
      {"honeycomb/course", {{1.56, 0.82, 14.3}, {1.48, 0.79, 13.8}}},
      {"honeycomb/wale", {{3.54, 1.10, 25.7}, {4.32, 1.26, 27.3}}},
      {"cartridge/course", {{0.34, 0.82, 12.2}, {0.41, 0.83, 15.6}}},
      {"cartridge/wale", {{6.03, 0.74, 11.3}, {NAN, NAN, NAN}}},
  };
  return t;
}

// Supplement Table 4 (wale): stress difference / Hausdorff for Bake-1, Bake-2, Bake-3, Neural.
const std::map<std::string, std::array<std::array<double, 2>, 4>>& paper_table4() {
  static const std::map<std::string, std::array<std::array<double, 2>, 4>> t = {
      {"basket", {{{0.93, 0.72}, {0.87, 0.69}, {0.87, 0.69}, {0.87, 0.69}}}},
      {"stockinette", {{{4.26, 0.82}, {3.08, 0.78}, {3.04, 0.75}, {3.04, 0.75}}}},
      {"honeycomb", {{{5.32, 1.42}, {3.63, 1.10}, {3.54, 1.10}, {3.54, 1.10}}}},
      {"cartridge", {{{7.39, 0.93}, {6.12, 0.81}, {6.02, 0.74}, {6.02, 0.74}}}},
  };
  return t;
}

// The paper's short name of a pattern file: basket, stockinette, honeycomb, cartridge.
std::string paper_name(const std::string& pattern) {
  const std::string stem = fs::path(pattern).stem().string();
  for (const char* n : {"basket", "stockinette", "honeycomb", "cartridge"})
    if (stem.find(n) != std::string::npos) return n;
  return stem;
}

std::string fmt(double x, const char* f = "%.2f") {
  if (std::isnan(x)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

void write_text(const fs::path& path, const std::string& text) {
  AtomicOutput out(path.string());
  {
    std::ofstream f(out.temp_path());
    f << text;
  }
  out.commit();
}

std::string plot_script(const std::string& name) { return scripts_dir() + "/plot/" + name; }

// Fig. 5: the yarn strip and the neural continuum strip at the step nearest 130 %, side by side.
// Pictures are a bonus: a missing python or a failed plot is reported, not fatal.
void fig5(const AccuracyResult& r, const AccuracyOptions& a, const std::string& title, const fs::path& png) {
  size_t k = 0;
  for (size_t j = 0; j < r.stretch.size(); ++j)
    if (std::abs(r.stretch[j] - 1.3) < std::abs(r.stretch[k] - 1.3)) k = j;
  char yname[32], cname[32];
  std::snprintf(yname, sizeof yname, "step_%03zu.obj", k);
  std::snprintf(cname, sizeof cname, "frame_%04zu.obj", k);
  const fs::path ydir = a.strip_dir.empty() ? fs::path(a.out) / "strip" : fs::path(a.strip_dir);
  const fs::path cdir = fs::path(a.out) / "sim_neural" / "frames";
  const std::string py = find_python("matplotlib, numpy");
  if (py.empty()) {
    std::printf("  (no python3 with matplotlib: no %s)\n", png.string().c_str());
    return;
  }
  const std::vector<std::string> argv = {py, plot_script("plot_fig5.py"), (ydir / "centrelines" / "step_000.obj").string(),
                                         (ydir / "centrelines" / yname).string(), (cdir / "frame_0000.obj").string(),
                                         (cdir / cname).string(), title, png.string()};
  if (run_child(argv, "/dev/null", "/dev/null") != 0) {
    std::string cmd;
    for (const std::string& a : argv) cmd += (cmd.empty() ? "" : " ") + shell_quote(a);
    std::printf("  (the Fig. 5 picture failed: %s)\n", cmd.c_str());
  }
}

CLI::App* study_group(CLI::App& app) {
  for (CLI::App* s : app.get_subcommands([](CLI::App*) { return true; }))
    if (s->get_name() == "study") return s;
  CLI::App* g = app.add_subcommand("study", "Studies that reproduce the supplement's tables (docs/accuracy.md)");
  g->require_subcommand(1);
  return g;
}

void add_accuracy_options(CLI::App* cmd, AccuracyOptions& a) {
  cmd->add_option("--preset", a.preset, "produce's sampling preset: quick or paper")
      ->check(CLI::IsMember({"quick", "paper"}))
      ->capture_default_str();
  cmd->add_option("--size", a.size, "Strip width,length in metres")->capture_default_str();
  cmd->add_option("--stretch", a.stretch, "Stretch ratios first:last:step")->capture_default_str();
  cmd->add_option("--epochs", a.epochs, "train-all's epochs per network (0: its default)")
      ->check(CLI::Range(0, 100000000))
      ->capture_default_str();
  cmd->add_option("--threads", a.threads, "Threads for produce and train-all (0: all cores)")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  cmd->add_option("--spacing", a.spacing, "Surface sampling of the Hausdorff distance, metres")
      ->check(finite_positive())
      ->capture_default_str();
  cmd->add_option("--strip-args", a.strip_args, "Extra arguments for strip");
  cmd->add_option("--sim-args", a.sim_args, "Extra arguments for sim stretch");
  cmd->add_flag("--force", a.force, "Rerun every stage");
}

}  // namespace

void register_study_accuracy(CLI::App& app) {
  CLI::App* study = study_group(app);

  // --- table5 ---------------------------------------------------------------------------
  {
    struct Opts {
      std::vector<std::string> patterns;
      std::vector<std::string> directions = {"course", "wale"};
      std::string out;
      AccuracyOptions acc;
    };
    auto o = std::make_shared<Opts>();
    o->acc.preset = "paper";
    auto* cmd = study->add_subcommand(
        "table5",
        "Supplement Table 5: the accuracy test (see `accuracy`) for every pattern and direction, "
        "neural material and spline baseline, written to OUT/table5.md and OUT/table5.csv beside "
        "the paper's figures. Patterns share their dataset and materials across directions.");
    cmd->add_option("PATTERNS", o->patterns, "Pattern files (.pyp) or built-in names: the paper's are basket, stockinette, slip_stitch_honeycomb, cartridge_belt_rib")
        ->required();
    cmd->add_option("--directions", o->directions, "Directions to test (comma-separated or repeated)")->delimiter(',')->check(CLI::IsMember({"course", "wale"}))->capture_default_str();
    cmd->add_option("-o,--output", o->out, "Output folder (created)")->required();
    add_accuracy_options(cmd, o->acc);
    cmd->callback([o] {
      check_output_folder(o->out);
      std::string md =
          "# Supplement Table 5, reproduced\n\nPer row: mean stress difference (N/m), mean Hausdorff distance (cm), mean "
          "relative stress error (%) over the tests, ours against the paper's.\n\n"
          "| pattern | direction | model | dN (N/m) | H (cm) | rel. err. (%) | ratio of means (%) | paper dN | paper H | paper rel. (%) |\n"
          "|---|---|---|---|---|---|---|---|---|---|\n";
      std::string csv = "pattern,direction,model,tests,mean_dN,mean_H_cm,mean_rel_pct,rel_tests,ratio_of_means_pct,paper_dN,paper_H_cm,paper_rel_pct\n";
      for (const std::string& p : o->patterns) {
        const std::string name = paper_name(p);
        for (const std::string& d : o->directions) {
          std::printf("\n== %s, %s\n", name.c_str(), d.c_str());
          AccuracyOptions a = o->acc;
          a.pattern = p;
          a.direction = d;
          a.materials_dir = (fs::path(o->out) / name).string();
          a.out = (fs::path(o->out) / name / d).string();
          const AccuracyResult r = run_accuracy(a);
          std::printf("%s", accuracy_report_text(r, a).c_str());
          fig5(r, a, name + " (" + d + "), 130 %: yarn level | continuum (neural)", fs::path(o->out) / ("fig5_" + name + "_" + d + ".png"));
          const auto it = paper_table5().find(name + "/" + d);
          for (const MaterialResult& m : r.materials) {
            const double* paper = nullptr;
            if (it != paper_table5().end()) paper = m.name == "neural" ? it->second.ours : it->second.hylc;
            const AccuracySummary& s = m.summary;
            const std::string label = m.failure.empty() ? m.name
                                                        : m.name + " (stopped after " + std::to_string(m.steps.size()) + " of " +
                                                              std::to_string(r.stretch.size()) + " tests)";
            md += "| " + name + " | " + d + " | " + label + " | " + fmt(s.mean_stress_diff) + " | " + fmt(100 * s.mean_hausdorff) +
                  " | " + fmt(100 * s.mean_rel_error) + " | " + fmt(100 * s.ratio_of_means) + " | " +
                  (paper ? fmt(paper[0]) + " | " + fmt(paper[1]) + " | " + fmt(paper[2]) : "- | - | -") + " |\n";
            csv += name + "," + d + "," + m.name + "," + std::to_string(s.tests) + "," + fmt(s.mean_stress_diff, "%.6g") + "," +
                   fmt(100 * s.mean_hausdorff, "%.6g") + "," + fmt(100 * s.mean_rel_error, "%.6g") + "," + std::to_string(s.rel_tests) +
                   "," + fmt(100 * s.ratio_of_means, "%.6g") + "," + (paper ? fmt(paper[0], "%g") + "," + fmt(paper[1], "%g") + "," + fmt(paper[2], "%g") : ",,") +
                   "\n";
          }
          // Written after every test, so an interrupted study keeps what it has.
          write_text(fs::path(o->out) / "table5.md", md);
          write_text(fs::path(o->out) / "table5.csv", csv);
        }
      }
      std::printf("\n%s\n-> %s/table5.md, table5.csv\n", md.c_str(), o->out.c_str());
    });
  }

  // --- bake-resolution -------------------------------------------------------------------
  {
    struct Opts {
      std::string pattern, out, direction = "wale";
      AccuracyOptions acc;
    };
    auto o = std::make_shared<Opts>();
    o->acc.preset = "paper";
    auto* cmd = study->add_subcommand(
        "bake-resolution",
        "Supplement Table 4: the accuracy test (wale by default) with the same networks baked at "
        "Bake-1 (1D 100 knots, 2D 25x25), Bake-2 (150, 50x50), Bake-3 (200, 100x100) and a "
        "reference bake fine enough to stand for the unbaked network (2000, 400x400: its deviation "
        "from the network is printed by bake), one yarn strip for all. OUT/table4.md and .csv.");
    cmd->add_option("PATTERN", o->pattern, "Pattern file (.pyp) or built-in name")->required();
    cmd->add_option("--direction", o->direction, "Stretch direction")->check(CLI::IsMember({"course", "wale"}))->capture_default_str();
    cmd->add_option("-o,--output", o->out, "Output folder (created)")->required();
    add_accuracy_options(cmd, o->acc);
    cmd->callback([o] {
      check_output_folder(o->out);
      const fs::path dir(o->out);
      const std::string name = paper_name(o->pattern);
      // The dataset and networks once (the accuracy test of the Bake-3 file makes them).
      AccuracyOptions base = o->acc;
      base.pattern = o->pattern;
      base.direction = o->direction;
      base.materials_dir = dir.string();
      base.strip_dir = (dir / "strip").string();
      base.spline = false;
      struct Bake {
        const char* label;
        int r1, r2;
      };
      const Bake bakes[] = {{"Bake-1", 100, 25}, {"Bake-2", 150, 50}, {"Bake-3", 200, 100}, {"network", 2000, 400}};
      std::string md = "# Supplement Table 4, reproduced (" + name + ", " + o->direction +
                       ")\n\nMean stress difference (N/m) / mean Hausdorff distance (cm) against the yarn strip.\n\n"
                       "| bake | 1D knots | 2D knots | ours dN / H | paper dN / H |\n|---|---|---|---|---|\n";
      std::string csv = "bake,knots1d,knots2d,mean_dN,mean_H_cm,mean_rel_pct,paper_dN,paper_H_cm\n";
      // The dataset and the networks once; every bake of them is tested against one yarn strip.
      const std::string model = (dir / "model.h5").string(), ds = (dir / "dataset.h5").string();
      std::vector<std::string> in;
      if (fs::exists(o->pattern)) in.push_back(o->pattern);
      std::vector<std::string> prod = {"produce", o->pattern, "-o", ds, "--preset", o->acc.preset};
      std::vector<std::string> train = {"train-all", ds, "-o", model, "-q"};
      if (o->acc.threads > 0) {
        for (auto* v : {&prod, &train}) { v->push_back("--threads"); v->push_back(std::to_string(o->acc.threads)); }
      }
      if (o->acc.epochs > 0) { train.push_back("--epochs"); train.push_back(std::to_string(o->acc.epochs)); }
      run_stage(dir, {"produce", prod, in, {ds}}, o->acc.force);
      run_stage(dir, {"train-all", train, {ds}, {model}}, o->acc.force);
      for (size_t k = 0; k < 4; ++k) {
        const Bake& b = bakes[k];
        const std::string baked = (dir / (std::string(b.label) + ".h5")).string();
        run_stage(dir, {std::string("bake-") + b.label,
                        {"bake", model, "-o", baked, "--data", ds, "--res1d", std::to_string(b.r1), "--res2d", std::to_string(b.r2)},
                        {model, ds},
                        {baked}},
                  o->acc.force);
        AccuracyOptions a = base;
        a.baked = baked;
        a.dataset = ds;
        a.out = (dir / b.label).string();
        const AccuracyResult r = run_accuracy(a);
        const AccuracySummary& s = r.materials[0].summary;
        const auto it = paper_table4().find(name);
        const std::string paper = it == paper_table4().end() ? "-" : fmt(it->second[k][0]) + " / " + fmt(it->second[k][1]);
        md += std::string("| ") + b.label + " | " + std::to_string(b.r1) + " | " + std::to_string(b.r2) + "x" + std::to_string(b.r2) +
              " | " + fmt(s.mean_stress_diff) + " / " + fmt(100 * s.mean_hausdorff) + " | " + paper + " |\n";
        csv += std::string(b.label) + "," + std::to_string(b.r1) + "," + std::to_string(b.r2) + "," + fmt(s.mean_stress_diff, "%.6g") +
               "," + fmt(100 * s.mean_hausdorff, "%.6g") + "," + fmt(100 * s.mean_rel_error, "%.6g") + "," +
               (it == paper_table4().end() ? "," : fmt(it->second[k][0], "%g") + "," + fmt(it->second[k][1], "%g")) + "\n";
        write_text(dir / "table4.md", md);
        write_text(dir / "table4.csv", csv);
      }
      std::printf("\n%s\n-> %s/table4.md, table4.csv\n", md.c_str(), o->out.c_str());
    });
  }
  // --- strip-width -----------------------------------------------------------------------
  {
    struct Opts {
      std::string pattern, out, direction = "wale", dataset, baked;
      std::vector<double> widths = {0.02, 0.04, 0.06, 0.08};
      double length = 0.04;
      bool no_plot = false;
      AccuracyOptions acc;
    };
    auto o = std::make_shared<Opts>();
    o->acc.preset = "paper";
    o->acc.stretch = "1.0:1.3:0.1";
    auto* cmd = study->add_subcommand(
        "strip-width",
        "Is the gap between a yarn strip and the continuum an edge effect? The accuracy test (see "
        "`accuracy`) on strips of one length and several widths, each yarn strip against a continuum "
        "strip of its own size, one neural material for all. A homogenized model describes the bulk, "
        "so an edge effect shows as a yarn force per width that approaches the continuum's as the "
        "strip widens. OUT/width.md, width.csv and width.png.");
    cmd->add_option("PATTERN", o->pattern, "Pattern (.pyp file or built-in name)")->required();
    cmd->add_option("--direction", o->direction, "Stretch direction")->check(CLI::IsMember({"course", "wale"}))->capture_default_str();
    cmd->add_option("--widths", o->widths, "Strip widths in metres (comma-separated or repeated)")
        ->delimiter(',')
        ->check(finite_positive())
        ->capture_default_str();
    cmd->add_option("--length", o->length, "Strip length in metres (along the stretch)")->check(finite_positive())->capture_default_str();
    cmd->add_option("--dataset", o->dataset, "Reuse this dataset instead of producing one")->check(existing_regular_file());
    cmd->add_option("--baked", o->baked, "Reuse this baked neural material instead of training and baking")->check(existing_regular_file());
    cmd->add_option("-o,--output", o->out, "Output folder (created)")->required();
    cmd->add_flag("--no-plot", o->no_plot, "Write no PNG");
    add_accuracy_options(cmd, o->acc);
    cmd->remove_option(cmd->get_option("--size"));
    cmd->callback([o] {
      check_output_folder(o->out);
      const fs::path dir(o->out);
      fs::create_directories(dir);
      const std::string name = paper_name(o->pattern);
      std::vector<double> widths = o->widths;
      std::sort(widths.begin(), widths.end());
      std::string md = "# Strip-width study (" + name + ", " + o->direction + ", length " + fmt(100 * o->length, "%g") +
                       " cm)\n\nClamp force per undeformed width (N/m), yarn strip / continuum strip of the same size, and the "
                       "mean relative stress error over the tests beyond 100 %.\n\n";
      std::string csv = "width_m,length_m,stretch,N_yarn,N_neural,dN\n";
      std::string header, rule;
      for (double w : widths) {
        char sz[64];
        std::snprintf(sz, sizeof sz, "%.6g,%.6g", w, o->length);
        char label[32];
        std::snprintf(label, sizeof label, "w_%.4g", w);
        std::printf("\n== width %s m\n", fmt(w, "%g").c_str());
        AccuracyOptions a = o->acc;
        a.pattern = o->pattern;
        a.direction = o->direction;
        a.size = sz;
        a.dataset = o->dataset;
        a.baked = o->baked;
        a.materials_dir = dir.string();  // one dataset and one material for every width
        a.out = (dir / label).string();
        a.spline = false;
        const AccuracyResult r = run_accuracy(a);
        const MaterialResult& m = r.materials[0];
        if (header.empty()) {
          header = "| width (cm) |";
          rule = "|---|";
          for (double s : r.stretch) {
            header += " " + fmt(100 * s, "%.0f") + " % |";
            rule += "---|";
          }
          md += header + " rel. err. beyond 100 % (%) |\n" + rule + "---|\n";
        }
        md += "| " + fmt(100 * w, "%g") + " |";
        for (size_t k = 0; k < r.stretch.size(); ++k) {
          md += " " + fmt(r.n_yarn[k]) + " / " + (k < m.steps.size() ? fmt(m.steps[k].n_cont) : std::string("-")) + " |";
          if (k < m.steps.size())
            csv += fmt(w, "%.6g") + "," + fmt(o->length, "%.6g") + "," + fmt(r.stretch[k], "%.6g") + "," + fmt(r.n_yarn[k], "%.6g") + "," +
                   fmt(m.steps[k].n_cont, "%.6g") + "," + fmt(m.steps[k].stress_diff, "%.6g") + "\n";
        }
        // The relaxed 100 % row is left out of the relative error: both forces are near zero
        // there, so the ratio measures noise.
        double rel = 0;
        int nrel = 0;
        for (size_t k = 0; k < m.steps.size(); ++k)
          if (r.stretch[k] > 1.0 + 1e-9 && r.n_yarn[k] != 0.0) {
            rel += m.steps[k].stress_diff / std::abs(r.n_yarn[k]);
            ++nrel;
          }
        md += " " + (nrel ? fmt(100 * rel / nrel) : std::string("-")) + " |\n";
        // Written after every width, so an interrupted study keeps what it has.
        write_text(dir / "width.md", md);
        write_text(dir / "width.csv", csv);
      }
      std::printf("\n%s\n-> %s/width.md, width.csv\n", md.c_str(), o->out.c_str());
      if (o->no_plot) return;
      const std::string py = find_python("matplotlib");
      const std::string png = (dir / "width.png").string();
      if (py.empty()) {
        std::printf("  (no python3 with matplotlib: no %s)\n", png.c_str());
        return;
      }
      const std::vector<std::string> argv = {py, plot_script("plot_study.py"), "strip-width", (dir / "width.csv").string(), png,
                                             name + ", " + o->direction + ", length " + fmt(100 * o->length, "%g") + " cm"};
      if (run_child(argv, "/dev/null", "") != 0)
        std::printf("  (drawing %s failed; the numbers are in width.csv)\n", png.c_str());
      else
        std::printf("wrote %s\n", png.c_str());
    });
  }
  // --- rve-size --------------------------------------------------------------------------
  {
    struct Opts {
      std::string pattern, out, direction = "wale";
      std::vector<int> tiles = {1, 2, 3};
      AccuracyOptions acc;
    };
    auto o = std::make_shared<Opts>();
    o->acc.preset = "paper";
    auto* cmd = study->add_subcommand(
        "rve-size",
        "Supplement Table 2: datasets produced on periodic patches of n x n tiles of the pattern "
        "(1, 2, 3 by default), each trained, baked and tested against the same yarn strip "
        "(wale by default): production time and mean stress difference. OUT/table2.md and .csv.");
    cmd->add_option("PATTERN", o->pattern, "Pattern file (.pyp)")->required()->check(existing_regular_file());
    cmd->add_option("--tiles", o->tiles, "Patch sizes n (n x n tiles; comma-separated or repeated)")->delimiter(',')->check(CLI::Range(1, 8))->capture_default_str();
    cmd->add_option("--direction", o->direction, "Stretch direction")->check(CLI::IsMember({"course", "wale"}))->capture_default_str();
    cmd->add_option("-o,--output", o->out, "Output folder (created)")->required();
    add_accuracy_options(cmd, o->acc);
    cmd->callback([o] {
      check_output_folder(o->out);
      const fs::path dir(o->out);
      fs::create_directories(dir);
      std::string md = "# Supplement Table 2, reproduced (" + paper_name(o->pattern) + ", " + o->direction +
                       ")\n\nPer RVE: produce time and mean stress difference (N/m) against the yarn strip. The paper's RVEs "
                       "are 1.8, 2.2, 2.6 and 3.0 times the pattern (not whole tiles); ours are whole n x n tiles.\n\n"
                       "| RVE | produce time | mean dN (N/m) | mean H (cm) | mean rel. err. (%) |\n|---|---|---|---|---|\n";
      std::string csv = "tiles,produce_seconds,mean_dN,mean_H_cm,mean_rel_pct\n";
      for (int n : o->tiles) {
        const std::string label = std::to_string(n) + "x" + std::to_string(n);
        const fs::path sub = dir / ("tiles_" + label);
        fs::create_directories(sub);
        // The patch, under the pattern's own file name (produce takes the paper's bending range
        // from it).
        const fs::path patch = sub / fs::path(o->pattern).filename();
        if (!fs::exists(patch) || fs::last_write_time(patch) < fs::last_write_time(o->pattern))
          yarn::write_pyp(patch.string(), yarn::tile(yarn::read_pyp(o->pattern), n, n));
        const std::string ds = (sub / "dataset.h5").string();
        std::vector<std::string> prod = {"produce", patch.string(), "-o", ds, "--preset", o->acc.preset};
        if (o->acc.threads > 0) { prod.push_back("--threads"); prod.push_back(std::to_string(o->acc.threads)); }
        const StageOutcome po = run_stage(sub, {"produce", prod, {patch.string()}, {ds}}, o->acc.force);
        // The production time survives reruns that skip the stage.
        const fs::path tfile = sub / "produce_seconds.txt";
        if (po.ran) write_text(tfile, fmt(po.seconds, "%.3f") + "\n");
        double secs = NAN;
        if (std::ifstream tf(tfile); tf) tf >> secs;
        AccuracyOptions a = o->acc;
        a.pattern = o->pattern;  // the strip is always made of the pattern itself
        a.direction = o->direction;
        a.dataset = ds;
        a.materials_dir = sub.string();
        a.strip_dir = (dir / "strip").string();
        a.out = (sub / "test").string();
        a.spline = false;
        const AccuracyResult r = run_accuracy(a);
        const AccuracySummary& s = r.materials[0].summary;
        md += "| " + label + " | " + (std::isnan(secs) ? std::string("-") : format_seconds(secs)) + " | " + fmt(s.mean_stress_diff) + " | " +
              fmt(100 * s.mean_hausdorff) + " | " + fmt(100 * s.mean_rel_error) + " |\n";
        csv += std::to_string(n) + "," + fmt(secs, "%.3f") + "," + fmt(s.mean_stress_diff, "%.6g") + "," + fmt(100 * s.mean_hausdorff, "%.6g") +
               "," + fmt(100 * s.mean_rel_error, "%.6g") + "\n";
        write_text(dir / "table2.md", md);
        write_text(dir / "table2.csv", csv);
      }
      std::printf("\n%s\n-> %s/table2.md, table2.csv\n", md.c_str(), o->out.c_str());
    });
  }
}

}  // namespace yarnhom::tools
