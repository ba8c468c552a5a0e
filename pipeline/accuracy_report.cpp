// The accuracy test's report (pipeline/accuracy_run.hpp): the table per stretch, the means, where
// the continuum strips left the data's boxes, the strips' transverse contraction, and the fabric
// without its boundary yarn.
#include <cmath>
#include <cstdio>

#include "core/console.hpp"
#include "pipeline/accuracy_run.hpp"

namespace yarnhom::pipeline {

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

}  // namespace yarnhom::pipeline
