// yarnhom study table5: supplement Table 5 (pipeline/study.hpp).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "core/file_checks.hpp"
#include "core/text_file.hpp"
#include "pipeline/rank_tasks.hpp"
#include "pipeline/study.hpp"
#include "pipeline/study_util.hpp"

namespace yarnhom::pipeline {

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

// The rows of one test (one pattern and direction): one per material.
void add_rows(const std::string& name, const std::string& d, const AccuracyResult& r, std::string& md, std::string& csv) {
  const auto it = paper_table5().find(name + "/" + d);
  for (const MaterialResult& m : r.materials) {
    const double* paper = nullptr;
    if (it != paper_table5().end()) paper = m.name == "neural" ? it->second.ours : it->second.hylc;
    const AccuracySummary& s = m.summary;
    const std::string label = m.failure.empty() ? m.name
                                                : m.name + " (stopped after " + std::to_string(m.steps.size()) + " of " +
                                                      std::to_string(r.stretch.size()) + " tests)";
    md += "| " + name + " | " + d + " | " + label + " | " + summary_md(s) + " | " + fmt(100 * s.mean_rel_error) + " | " +
          fmt(100 * s.ratio_of_means) + " | " +
          (paper ? fmt(paper[0]) + " | " + fmt(paper[1]) + " | " + fmt(paper[2]) : "- | - | -") + " |\n";
    csv += name + "," + d + "," + m.name + "," + std::to_string(s.tests) + "," + summary_csv(s) + "," +
           std::to_string(s.rel_tests) + "," + fmt(100 * s.ratio_of_means, "%.6g") + "," +
           (paper ? fmt(paper[0], "%g") + "," + fmt(paper[1], "%g") + "," + fmt(paper[2], "%g") : ",,") + "\n";
  }
}

}  // namespace

void run_study_table5(const Table5Options& o) {
  check_output_folder(o.out);
  auto row = [&o](const std::string& p, const std::string& d) {
    const std::string name = paper_name(p);
    return row_test(o.acc, p, d, (fs::path(o.out) / name).string(), (fs::path(o.out) / name / d).string());
  };
  // On several ranks (pipeline/rank_tasks.hpp): the rows' pieces first, then rank 0 alone.
  const OnRanks ranks(o.out, "study table5", [&](RankTasks& g) {
    for (const std::string& p : o.patterns)
      for (const std::string& d : o.directions) add_accuracy_tasks(g, row(p, d), paper_name(p) + ", " + d);
  });
  if (!ranks.root()) return;
  std::string md =
      "# Supplement Table 5, reproduced\n\nPer row: mean stress difference (N/m), mean Hausdorff distance (cm), mean "
      "relative stress error (%) over the tests, ours against the paper's.\n\n"
      "| pattern | direction | model | dN (N/m) | H (cm) | rel. err. (%) | ratio of means (%) | paper dN | paper H | paper rel. (%) |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n";
  std::string csv = "pattern,direction,model,tests,mean_dN,mean_H_cm,mean_rel_pct,rel_tests,ratio_of_means_pct,paper_dN,paper_H_cm,paper_rel_pct\n";
  const auto t0 = std::chrono::steady_clock::now();
  const int tests = int(o.patterns.size() * o.directions.size());
  int k = 0;
  for (const std::string& p : o.patterns) {
    const std::string name = paper_name(p);
    for (const std::string& d : o.directions) {
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("\n== %s, %s (%s)\n", name.c_str(), d.c_str(), study_progress(k, tests, el, k, tests).c_str());
      std::fflush(stdout);
      ++k;
      const AccuracyOptions a = row(p, d);
      const AccuracyResult r = run_accuracy(a);
      std::printf("%s", accuracy_report_text(r, a).c_str());
      fig5(r, a, name + " (" + d + "), 130 %: yarn level | continuum (neural)", fs::path(o.out) / ("fig5_" + name + "_" + d + ".png"));
      add_rows(name, d, r, md, csv);
      // Written after every test, so an interrupted study keeps what it has.
      write_text_file((fs::path(o.out) / "table5.md").string(), md);
      write_text_file((fs::path(o.out) / "table5.csv").string(), csv);
    }
  }
  std::printf("\n%s\n-> %s/table5.md, table5.csv\n", md.c_str(), o.out.c_str());
}

}  // namespace yarnhom::pipeline
