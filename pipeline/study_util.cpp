#include "pipeline/study_util.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/console.hpp"
#include "pipeline/child_process.hpp"
#include "pipeline/python_env.hpp"
#include "pipeline/stage_runner.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

std::string paper_name(const std::string& pattern) {
  const std::string stem = fs::path(pattern).stem().string();
  for (const char* n : {"basket", "stockinette", "honeycomb", "cartridge"})
    if (stem.find(n) != std::string::npos) return n;
  return stem;
}

std::string fmt(double x, const char* f) {
  if (std::isnan(x)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

std::string plot_script(const std::string& name) { return scripts_dir() + "/plot/" + name; }

AccuracyOptions row_test(const AccuracyOptions& acc, const std::string& pattern, const std::string& direction,
                         const std::string& materials_dir, const std::string& out) {
  AccuracyOptions a = acc;
  a.pattern = pattern;
  a.direction = direction;
  a.materials_dir = materials_dir;
  a.out = out;
  return a;
}

std::string summary_md(const AccuracySummary& s, const char* sep) {
  return fmt(s.mean_stress_diff) + sep + fmt(100 * s.mean_hausdorff);
}

std::string summary_csv(const AccuracySummary& s) {
  return fmt(s.mean_stress_diff, "%.6g") + "," + fmt(100 * s.mean_hausdorff, "%.6g") + "," +
         fmt(100 * s.mean_rel_error, "%.6g");
}

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

std::string study_progress(int k, int n, double elapsed, double work_done, double work_total) {
  std::string out = "part " + std::to_string(k + 1) + " of " + std::to_string(n);
  if (k > 0 && work_done > 0)
    out += ", elapsed " + format_seconds(elapsed) + ", ETA " +
           format_seconds(elapsed / work_done * std::max(0.0, work_total - work_done)) + " at the pace so far";
  return out;
}

}  // namespace yarnhom::pipeline
