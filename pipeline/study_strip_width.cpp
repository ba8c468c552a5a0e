// yarnhom study strip-width: is the gap between a yarn strip and the continuum an edge effect?
// (pipeline/study.hpp)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/file_checks.hpp"
#include "core/text_file.hpp"
#include "pipeline/child_process.hpp"
#include "pipeline/python_env.hpp"
#include "pipeline/rank_tasks.hpp"
#include "pipeline/study.hpp"
#include "pipeline/study_util.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

namespace {

// The table's header, from the first test's stretch ratios.
std::string width_header(const AccuracyResult& r) {
  std::string header = "| width (cm) |", rule = "|---|";
  for (double s : r.stretch) {
    header += " " + fmt(100 * s, "%.0f") + " % |";
    rule += "---|";
  }
  return header + " rel. err. beyond 100 % (%) |\n" + rule + "---|\n";
}

// One width's row: yarn / continuum force per stretch and the mean relative error; its CSV rows.
void add_width_rows(const StripWidthOptions& o, double w, const AccuracyResult& r, std::string& md, std::string& csv) {
  const MaterialResult& m = r.materials[0];
  md += "| " + fmt(100 * w, "%g") + " |";
  for (size_t k = 0; k < r.stretch.size(); ++k) {
    md += " " + fmt(r.n_yarn[k]) + " / " + (k < m.steps.size() ? fmt(m.steps[k].n_cont) : std::string("-")) + " |";
    if (k < m.steps.size())
      csv += fmt(w, "%.6g") + "," + fmt(o.length, "%.6g") + "," + fmt(r.stretch[k], "%.6g") + "," + fmt(r.n_yarn[k], "%.6g") + "," +
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
}

void plot_widths(const StripWidthOptions& o, const fs::path& dir, const std::string& name) {
  const std::string py = find_python("matplotlib");
  const std::string png = (dir / "width.png").string();
  if (py.empty()) {
    std::printf("  (no python3 with matplotlib: no %s)\n", png.c_str());
    return;
  }
  const std::vector<std::string> argv = {py, plot_script("plot_study.py"), "strip-width", (dir / "width.csv").string(), png,
                                         name + ", " + o.direction + ", length " + fmt(100 * o.length, "%g") + " cm"};
  if (run_child(argv, "/dev/null", "") != 0)
    std::printf("  (drawing %s failed; the numbers are in width.csv)\n", png.c_str());
  else
    std::printf("wrote %s\n", png.c_str());
}

}  // namespace

void run_study_strip_width(const StripWidthOptions& o) {
  check_output_folder(o.out);
  const fs::path dir(o.out);
  fs::create_directories(dir);
  const std::string name = paper_name(o.pattern);
  std::vector<double> widths = o.widths;
  std::sort(widths.begin(), widths.end());
  // One dataset and one material for every width.
  auto row = [&](double w) {
    char sz[64], label[32];
    std::snprintf(sz, sizeof sz, "%.6g,%.6g", w, o.length);
    std::snprintf(label, sizeof label, "w_%.4g", w);
    AccuracyOptions a = row_test(o.acc, o.pattern, o.direction, dir.string(), (dir / label).string());
    a.size = sz;
    a.dataset = o.dataset;
    a.baked = o.baked;
    a.spline = false;
    return a;
  };
  // On several ranks (pipeline/rank_tasks.hpp): the widths' pieces first, then rank 0 alone.
  const OnRanks ranks(dir, "study strip-width", [&](RankTasks& g) {
    for (double w : widths) add_accuracy_tasks(g, row(w), "width " + fmt(w, "%g") + " m");
  });
  if (!ranks.root()) return;
  std::string md = "# Strip-width study (" + name + ", " + o.direction + ", length " + fmt(100 * o.length, "%g") +
                   " cm)\n\nClamp force per undeformed width (N/m), yarn strip / continuum strip of the same size, and the "
                   "mean relative stress error over the tests beyond 100 %.\n\n";
  std::string csv = "width_m,length_m,stretch,N_yarn,N_neural,dN\n";
  bool first = true;
  const auto t0 = std::chrono::steady_clock::now();
  double area_done = 0, area_total = 0;  // the strips' cost grows with their width
  for (double w : widths) area_total += w;
  int k = 0;
  for (double w : widths) {
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("\n== width %s m (%s)\n", fmt(w, "%g").c_str(),
                study_progress(k++, int(widths.size()), el, area_done, area_total).c_str());
    std::fflush(stdout);
    area_done += w;
    const AccuracyResult r = run_accuracy(row(w));
    if (first) md += width_header(r);
    first = false;
    add_width_rows(o, w, r, md, csv);
    // Written after every width, so an interrupted study keeps what it has.
    write_text_file((dir / "width.md").string(), md);
    write_text_file((dir / "width.csv").string(), csv);
  }
  std::printf("\n%s\n-> %s/width.md, width.csv\n", md.c_str(), o.out.c_str());
  if (!o.no_plot) plot_widths(o, dir, name);
}

}  // namespace yarnhom::pipeline
