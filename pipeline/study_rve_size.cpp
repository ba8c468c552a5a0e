// yarnhom study rve-size: supplement Table 2 (pipeline/study.hpp).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/console.hpp"
#include "core/file_checks.hpp"
#include "core/text_file.hpp"
#include "pipeline/rank_tasks.hpp"
#include "pipeline/stage_runner.hpp"
#include "pipeline/study.hpp"
#include "pipeline/study_util.hpp"
#include "yarn/rod/load_pattern.hpp"
#include "yarn/rod/pattern.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

namespace {

// The n x n patch's dataset in `sub`; returns the production time (NaN when unknown), which
// survives reruns that skip the stage.
double produce_patch(const RveSizeOptions& o, const fs::path& sub, int n, const std::string& ds) {
  fs::create_directories(sub);
  // The patch, under the pattern's own file name (produce takes the paper's bending range
  // from it; a built-in pattern under its name, e.g. stockinette.pyp).
  const bool file = fs::exists(o.pattern);
  const fs::path patch = sub / (file ? fs::path(o.pattern).filename() : fs::path(o.pattern + ".pyp"));
  if (!fs::exists(patch) || (file && fs::last_write_time(patch) < fs::last_write_time(o.pattern)))
    yarn::write_pyp(patch.string(), yarn::tile(yarn::load_pattern(o.pattern), n, n));
  const StageOutcome po =
      run_stage(sub, {"produce", produce_stage_args(patch.string(), ds, o.acc.preset, o.acc.threads), {patch.string()}, {ds}},
                o.acc.force);
  const fs::path tfile = sub / "produce_seconds.txt";
  if (po.ran) write_text_file(tfile.string(), fmt(po.seconds, "%.3f") + "\n");
  double secs = NAN;
  if (std::ifstream tf(tfile); tf) tf >> secs;
  return secs;
}

}  // namespace

void run_study_rve_size(const RveSizeOptions& o) {
  check_output_folder(o.out);
  const fs::path dir(o.out);
  fs::create_directories(dir);
  auto sub_of = [&](int n) { return dir / ("tiles_" + std::to_string(n) + "x" + std::to_string(n)); };
  // The strip is always made of the pattern itself.
  auto row = [&](int n) {
    AccuracyOptions a = row_test(o.acc, o.pattern, o.direction, sub_of(n).string(), (sub_of(n) / "test").string());
    a.dataset = (sub_of(n) / "dataset.h5").string();
    a.strip_dir = (dir / "strip").string();
    a.spline = false;
    return a;
  };
  // On several ranks (pipeline/rank_tasks.hpp): the patches' datasets and tests first, then rank 0 alone.
  const OnRanks ranks(dir, "study rve-size", [&](RankTasks& g) {
    for (int n : o.tiles) {
      const std::string label = std::to_string(n) + "x" + std::to_string(n);
      const int made = g.add((sub_of(n) / ".stages" / "produce").string(), label + ": produce (" + o.acc.preset + ")",
                             produce_task_weight(o.acc.preset, n), {},
                             [&o, n, sub = sub_of(n)] { produce_patch(o, sub, n, (sub / "dataset.h5").string()); });
      add_accuracy_tasks(g, row(n), label, {made});
    }
  });
  if (!ranks.root()) return;
  std::string md = "# Supplement Table 2, reproduced (" + paper_name(o.pattern) + ", " + o.direction +
                   ")\n\nPer RVE: produce time and mean stress difference (N/m) against the yarn strip. The paper's RVEs "
                   "are 1.8, 2.2, 2.6 and 3.0 times the pattern (not whole tiles); ours are whole n x n tiles.\n\n"
                   "| RVE | produce time | mean dN (N/m) | mean H (cm) | mean rel. err. (%) |\n|---|---|---|---|---|\n";
  std::string csv = "tiles,produce_seconds,mean_dN,mean_H_cm,mean_rel_pct\n";
  for (int n : o.tiles) {
    const std::string label = std::to_string(n) + "x" + std::to_string(n);
    const double secs = produce_patch(o, sub_of(n), n, (sub_of(n) / "dataset.h5").string());
    const AccuracySummary s = run_accuracy(row(n)).materials[0].summary;
    md += "| " + label + " | " + (std::isnan(secs) ? std::string("-") : format_seconds(secs)) + " | " + summary_md(s) + " | " +
          fmt(100 * s.mean_rel_error) + " |\n";
    csv += std::to_string(n) + "," + fmt(secs, "%.3f") + "," + summary_csv(s) + "\n";
    write_text_file((dir / "table2.md").string(), md);
    write_text_file((dir / "table2.csv").string(), csv);
  }
  std::printf("\n%s\n-> %s/table2.md, table2.csv\n", md.c_str(), o.out.c_str());
}

}  // namespace yarnhom::pipeline
