#include "pipeline/run_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "bake/rest_check.hpp"
#include "core/baked.hpp"
#include "core/console.hpp"
#include "core/dataset.hpp"
#include "core/file_checks.hpp"
#include "core/fit_metrics.hpp"
#include "core/model.hpp"
#include "pipeline/stage_runner.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

namespace {

struct RunFiles {
  std::string ds, model, baked, errors, errors_csv, plots;
  explicit RunFiles(const fs::path& run)
      : ds((run / "dataset.h5").string()), model((run / "model.h5").string()), baked((run / "baked.h5").string()),
        errors((run / "errors.txt").string()), errors_csv((run / "errors.csv").string()),
        plots((run / "plots" / "plotdata.h5").string()) {}
};

std::vector<StageSpec> pipeline_stages(const PipelineOptions& o, const std::vector<std::string>& commands, const RunFiles& f) {
  std::vector<StageSpec> stages;
  if (o.pattern == "synthetic") {
    stages.push_back({"produce", {"synth", "-o", f.ds, "--preset", o.preset}, {}, {f.ds}});
  } else {
    if (std::find(commands.begin(), commands.end(), "produce") == commands.end())
      throw std::invalid_argument(
          "this build has no 'produce' command (the yarn RVE producer), so only PATTERN "
          "'synthetic' can run; try: yarnhom pipeline synthetic -o " + o.run);
    // A pattern file is an input of the stage (rerun when it changes); a built-in pattern name
    // is passed through for produce to resolve.
    std::vector<std::string> in;
    if (fs::exists(o.pattern)) in.push_back(o.pattern);
    std::vector<std::string> args = {"produce", o.pattern, "-o", f.ds, "--preset", o.preset};
    add_count_option(args, "--threads", o.threads);
    stages.push_back({"produce", args, in, {f.ds}});
  }
  std::vector<std::string> train = {"train-all", f.ds, "-o", f.model, "--backend", o.backend, "-q", "--recipe", o.recipe};
  add_count_option(train, "--threads", o.threads);
  add_count_option(train, "--epochs", o.epochs);
  stages.push_back({"train-all", train, {f.ds}, {f.model}});
  stages.push_back({"bake", {"bake", f.model, "-o", f.baked, "--data", f.ds}, {f.model, f.ds}, {f.baked}});
  // error writes its report to stdout: kept as the stage's output file too.
  stages.push_back({"error", {"error", f.baked, "--model", f.model, "--data", f.ds, "--csv", f.errors_csv},
                    {f.baked, f.model, f.ds}, {f.errors, f.errors_csv}, f.errors});
  if (!o.no_plot) stages.push_back({"plot", {"plot", o.run}, {f.baked, f.model, f.ds}, {f.plots}});
  return stages;
}

// One line of `error --csv` in the report ("" for the header and the E row); E and the worst bake
// deviation gathered on the way.
struct ErrorsSummary {
  double worst = 0;
  std::string E = "?";
  int failed = 0, measured = 0;
  std::string lines;
};

void read_error_row(const std::string& row, ErrorsSummary& sum) {
  // Columns of `error --csv`; the last (the verdict) is quoted and may hold anything but a
  // double quote.
  std::vector<std::string> cols, tail;
  const size_t q = row.find('"'), q2 = row.rfind('"');
  std::string verdict = q == std::string::npos ? "" : row.substr(q + 1, q2 - q - 1);
  std::stringstream ss(q == std::string::npos ? row : row.substr(0, q));
  std::string c;
  while (std::getline(ss, c, ',')) cols.push_back(c);
  if (q != std::string::npos) {  // the columns after the quoted verdict
    std::stringstream st(row.substr(q2 + 1));
    while (std::getline(st, c, ',')) tail.push_back(c);
  }
  if (cols.size() >= 3 && cols[0] == "E") sum.E = cols[2];
  if (cols.empty() || cols[0] == "term" || cols[0] == "E") return;
  if (cols.size() >= 10 && !cols[9].empty()) sum.worst = std::max(sum.worst, std::stod(cols[9]));
  if (cols.size() < 17 || cols[12].empty()) return;
  ++sum.measured;
  sum.failed += cols[16] != "1";
  char buf[640];
  std::string baked_note;
  // tail: "", baked energy, baked gradient, baked ok
  if (tail.size() >= 4 && !tail[1].empty() && tail[3] != "1")
    baked_note = "; baked table: energy " + std::to_string(100 * std::stod(tail[1])).substr(0, 5) + "%, gradient " +
                 std::to_string(100 * std::stod(tail[2])).substr(0, 6) + "% (bake's " +
                 baked_table_cause(int(cols[0].size())) + "; docs/bake.md)";
  // tail[4]: the validation small-stress error of a 1D term (empty for 2D terms)
  char small[48] = "";
  if (tail.size() >= 5 && !tail[4].empty())
    std::snprintf(small, sizeof small, "  small stresses %5.1f%%", 100 * std::stod(tail[4]));
  std::snprintf(buf, sizeof buf, "    %-4s energy %6.2f%%  gradient %7.2f%%%s   %s%s\n", cols[0].c_str(),
                100 * std::stod(cols[12]), 100 * std::stod(cols[13]), small, verdict.c_str(), baked_note.c_str());
  sum.lines += buf;
}

void print_report(const PipelineOptions& o, const RunFiles& f, const std::vector<std::pair<std::string, double>>& times,
                  std::chrono::steady_clock::time_point t_all) {
  std::printf("\nreport (%s)\n", o.run.c_str());
  Model m = read_model(f.model);
  std::ifstream csv(f.errors_csv);
  ErrorsSummary sum;
  for (std::string row; std::getline(csv, row);) read_error_row(row, sum);
  std::printf("  %zu terms; validation fit of the networks (energy RMSE / data range, gradient error / mean "
              "gradient, and for 1D terms the small stresses' relative error; limits %g%%, %g%% (or 1.25 x data G where the "
              "data are rough) and %g%%):\n%s",
              m.networks.size(), 100 * kFitEnergyThreshold, 100 * kFitGradThreshold, 100 * kFitSmallStressThreshold,
              sum.lines.c_str());
  if (sum.measured)
    std::printf("  %s\n", sum.failed ? (std::to_string(sum.failed) + " of " + std::to_string(sum.measured) +
                                        " terms FAIL the limits: the material does not represent the data there").c_str()
                                     : "every term fits its validation data within the limits");
  std::printf("  quadratic expansion error E (Eq. 4) = %s J/m^2 (measures smoothness, not fit); worst bake "
              "deviation %.2e of a term's range\n", sum.E.c_str(), sum.worst);
  {
    // Is the material's rest stress free and stable? (bake/rest_check.hpp; the fit limits
    // above are relative to whole ranges and do not see the small strains near rest.)
    std::string missing;
    const BakedMaterial mat = make_baked_material(read_baked(f.baked), f.baked, &missing);
    std::printf("  %s%s\n", check_rest(mat).summary().c_str(), rve_rest_note(read_dataset(f.ds).rest_hessian).c_str());
  }
  for (const auto& [name, secs] : times) std::printf("  %s: %s\n", name.c_str(), format_seconds(secs).c_str());
  std::printf("  total %s\n", format_seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - t_all).count()).c_str());
  std::printf("  metrics: %s\n", f.errors.c_str());
  if (!o.no_plot) std::printf("  pictures: %s\n", (fs::path(o.run) / "plots").string().c_str());
}

}  // namespace

int run_pipeline(const PipelineOptions& o, const std::vector<std::string>& commands) {
  const auto t_all = std::chrono::steady_clock::now();
  const fs::path run(o.run);
  if (o.pattern == "synthetic" && o.preset == "tiny")
    throw std::invalid_argument("--preset tiny: produce's preset (5 / 3 x 3 points, for tests); synth, which 'synthetic' "
                                "runs, takes quick or paper");
  check_output_folder(o.run);
  if (o.pattern != "synthetic" && fs::exists(o.pattern)) check_input_file(o.pattern, "PATTERN");
  fs::create_directories(run / "logs");
  fs::create_directories(run / ".stages");
  const RunFiles f(run);
  const std::vector<StageSpec> stages = pipeline_stages(o, commands, f);
  std::printf("pipeline %s -> %s (preset %s, backend %s)\n", o.pattern.c_str(), o.run.c_str(), o.preset.c_str(),
              o.backend.c_str());
  std::vector<std::pair<std::string, double>> times;
  for (const StageSpec& s : stages) {
    const StageOutcome out = run_stage_child(run, s, o.force, 10);
    if (!out.ran) continue;
    times.emplace_back(s.name, out.seconds);
    if (out.status == 0) continue;
    if (s.name == "plot") {  // pictures are a bonus: report, do not fail the run
      std::printf(" failed (see %s); continuing without pictures\n", out.log.c_str());
      continue;
    }
    std::printf(" failed after %s (see %s)\n", format_seconds(out.seconds).c_str(),
                s.stdout_file.empty() ? out.log.c_str() : s.stdout_file.c_str());
    if (!s.stdout_file.empty()) fs::remove(s.stdout_file);
    return 1;
  }
  print_report(o, f, times, t_all);
  return 0;
}

}  // namespace yarnhom::pipeline
