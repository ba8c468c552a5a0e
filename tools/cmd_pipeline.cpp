// yarnhom pipeline: produce -> train-all -> bake -> error -> plot in one command, each stage
// skipped when its output is already there, newer than its input and made with the same
// settings (bake/pipeline_stage.hpp), so a rerun after an interruption continues.
//
// Each stage runs as this same program with the stage's subcommand, in a child process, with its
// output in RUN_DIR/logs/<stage>.log: the stages stay exactly the commands a user can run by
// hand, and one failing stage cannot leave the pipeline in a half state (outputs are atomic).
// A stage dies with the pipeline (tools/child_process.hpp): killing the pipeline, even with
// SIGKILL, never leaves a stage running that would race a rerun.
//
// PATTERN "synthetic" uses `synth` (the analytic stand-in, docs/synthetic.md). Any other PATTERN
// (a .pyp file or a built-in pattern name) goes to the `produce` subcommand (the yarn RVE
// producer); the pipeline uses it when this build has it and says so when it does not.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "bake/pipeline_stage.hpp"
#include "bake/rest_check.hpp"
#include "core/fit_metrics.hpp"
#include "core/model.hpp"
#include "tools/child_process.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"

namespace yarnhom::tools {

namespace fs = std::filesystem;

namespace {

struct Stage {
  std::string name;
  std::vector<std::string> args;  // subcommand and its arguments
  std::vector<std::string> inputs, outputs;
};

}  // namespace

void register_pipeline(CLI::App& app) {
  struct Opts {
    std::string pattern, run, preset = "quick", backend = "cpu", recipe = "default";
    int threads = 0, epochs = 0;
    bool force = false;
    bool no_plot = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* parent = &app;
  auto* cmd = app.add_subcommand(
      "pipeline",
      "Run the whole pipeline into RUN_DIR: produce (or synth for PATTERN 'synthetic') -> "
      "train-all -> bake -> error -> plot. Each stage is skipped when its output exists, is newer "
      "than its input and was made with the same settings, so a rerun after an interruption "
      "continues. Ends with a short report. Stage logs: RUN_DIR/logs/.");
  cmd->add_option("PATTERN", o->pattern, "A pattern for produce (.pyp file or built-in name), or 'synthetic'")->required();
  cmd->add_option("-o,--output", o->run, "Run folder (created)")->required();
  cmd->add_option("--preset", o->preset, "Sampling density: quick or paper")
      ->check(CLI::IsMember({"quick", "paper"}))
      ->capture_default_str();
  cmd->add_option("--backend", o->backend, "Training backend: cpu or cuda")->check(backend_validator())->capture_default_str();
  cmd->add_option("--threads", o->threads, "CPU threads for training (0: all cores)")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  cmd->add_option("--epochs", o->epochs, "Epochs per network (0: the paper's 500)")
      ->check(CLI::Range(0, 100000000))
      ->capture_default_str();
  cmd->add_option("--recipe", o->recipe, "Training recipe, as train-all's --recipe: default, paper or improved")
      ->check(CLI::IsMember({"default", "paper", "improved"}))
      ->capture_default_str();
  cmd->add_flag("--force", o->force, "Rerun every stage");
  cmd->add_flag("--no-plot", o->no_plot, "Skip the plot stage (no PNGs; the metrics are in errors.txt)");
  cmd->callback([o, parent] {
    const auto t_all = std::chrono::steady_clock::now();
    const fs::path run(o->run);
    check_output_folder(o->run);
    if (o->pattern != "synthetic" && fs::exists(o->pattern)) check_input_file(o->pattern, "PATTERN");
    fs::create_directories(run / "logs");
    fs::create_directories(run / ".stages");
    const std::string exe = fs::read_symlink("/proc/self/exe").string();
    const std::string ds = (run / "dataset.h5").string(), model = (run / "model.h5").string(),
                      baked = (run / "baked.h5").string(), errors = (run / "errors.txt").string(),
                      errors_csv = (run / "errors.csv").string(), plots = (run / "plots" / "plotdata.h5").string();
    const bool synthetic = o->pattern == "synthetic";
    bool have_produce = false;
    for (CLI::App* sub : parent->get_subcommands([](CLI::App*) { return true; }))
      have_produce = have_produce || sub->get_name() == "produce";
    std::vector<Stage> stages;
    if (synthetic) {
      stages.push_back({"produce", {"synth", "-o", ds, "--preset", o->preset}, {}, {ds}});
    } else {
      if (!have_produce)
        throw std::invalid_argument(
            "this build has no 'produce' command (the yarn RVE producer), so only PATTERN "
            "'synthetic' can run; try: yarnhom pipeline synthetic -o " + o->run);
      // A pattern file is an input of the stage (rerun when it changes); a built-in pattern name
      // is passed through for produce to resolve.
      std::vector<std::string> in;
      if (fs::exists(o->pattern)) in.push_back(o->pattern);
      std::vector<std::string> args = {"produce", o->pattern, "-o", ds, "--preset", o->preset};
      if (o->threads > 0) { args.push_back("--threads"); args.push_back(std::to_string(o->threads)); }
      stages.push_back({"produce", args, in, {ds}});
    }
    std::vector<std::string> train = {"train-all", ds, "-o", model, "--backend", o->backend, "-q",
                                      "--recipe", o->recipe};
    if (o->threads > 0) { train.push_back("--threads"); train.push_back(std::to_string(o->threads)); }
    if (o->epochs > 0) { train.push_back("--epochs"); train.push_back(std::to_string(o->epochs)); }
    stages.push_back({"train-all", train, {ds}, {model}});
    stages.push_back({"bake", {"bake", model, "-o", baked, "--data", ds}, {model, ds}, {baked}});
    stages.push_back({"error", {"error", baked, "--model", model, "--data", ds, "--csv", errors_csv}, {baked, model, ds}, {errors, errors_csv}});
    if (!o->no_plot) stages.push_back({"plot", {"plot", o->run}, {baked, model, ds}, {plots}});

    std::printf("pipeline %s -> %s (preset %s, backend %s)\n", o->pattern.c_str(), o->run.c_str(), o->preset.c_str(),
                o->backend.c_str());
    std::vector<std::pair<std::string, double>> times;
    for (const Stage& s : stages) {
      std::string settings;
      for (const std::string& a : s.args) settings += a + "\n";
      const std::string stamp = (run / ".stages" / (s.name + ".done")).string();
      StageDecision d = stage_decision(s.inputs, s.outputs, stamp, settings);
      if (o->force) d = {true, "--force"};
      if (!d.run) {
        std::printf("  %-10s skipped (up to date)\n", s.name.c_str());
        continue;
      }
      std::printf("  %-10s running (%s) ...", s.name.c_str(), d.reason.c_str());
      std::fflush(stdout);
      const std::string log = (run / "logs" / (s.name + ".log")).string();
      std::vector<std::string> argv = {exe};
      argv.insert(argv.end(), s.args.begin(), s.args.end());
      const auto t0 = std::chrono::steady_clock::now();
      // error writes its report to stdout: keep it as the stage's output file too.
      const int rc = run_child(argv, s.name == "error" ? errors : log, log);
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      times.emplace_back(s.name, secs);
      if (rc != 0 && s.name == "plot") {  // pictures are a bonus: report, do not fail the run
        std::printf(" failed (see %s); continuing without pictures\n", log.c_str());
        continue;
      }
      if (rc != 0) {
        std::printf(" failed after %s (see %s)\n", format_seconds(secs).c_str(), s.name == "error" ? errors.c_str() : log.c_str());
        if (s.name == "error") fs::remove(errors);
        throw ExitCode{1};
      }
      write_stage_stamp(stamp, settings);
      std::printf(" done in %s\n", format_seconds(secs).c_str());
    }

    // The report.
    std::printf("\nreport (%s)\n", o->run.c_str());
    Model m = read_model(model);
    std::ifstream csv(errors_csv);
    std::string row;
    double worst = 0;
    std::string E = "?";
    int failed = 0, measured = 0;
    std::string lines;
    while (std::getline(csv, row)) {
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
      if (cols.size() >= 3 && cols[0] == "E") E = cols[2];
      if (cols.empty() || cols[0] == "term" || cols[0] == "E") continue;
      if (cols.size() >= 10 && !cols[9].empty()) worst = std::max(worst, std::stod(cols[9]));
      if (cols.size() >= 17 && !cols[12].empty()) {
        ++measured;
        failed += cols[16] != "1";
        char buf[640];
        std::string baked_note;
        // tail: "", baked energy, baked gradient, baked ok
        if (tail.size() >= 4 && !tail[1].empty() && tail[3] != "1")
          baked_note = "; baked table: energy " + std::to_string(100 * std::stod(tail[1])).substr(0, 5) +
                       "%, gradient " + std::to_string(100 * std::stod(tail[2])).substr(0, 6) +
                       "% (bake's " + baked_table_cause(int(cols[0].size())) + "; docs/bake.md)";
        // tail[4]: the validation small-stress error of a 1D term (empty for 2D terms)
        char small[48] = "";
        if (tail.size() >= 5 && !tail[4].empty())
          std::snprintf(small, sizeof small, "  small stresses %5.1f%%", 100 * std::stod(tail[4]));
        std::snprintf(buf, sizeof buf, "    %-4s energy %6.2f%%  gradient %7.2f%%%s   %s%s\n", cols[0].c_str(),
                      100 * std::stod(cols[12]), 100 * std::stod(cols[13]), small, verdict.c_str(), baked_note.c_str());
        lines += buf;
      }
    }
    std::printf("  %zu terms; validation fit of the networks (energy RMSE / data range, gradient error / mean "
                "gradient, and for 1D terms the small stresses' relative error; limits %g%%, %g%% and %g%%):\n%s",
                m.networks.size(), 100 * kFitEnergyThreshold, 100 * kFitGradThreshold, 100 * kFitSmallStressThreshold,
                lines.c_str());
    if (measured)
      std::printf("  %s\n", failed ? (std::to_string(failed) + " of " + std::to_string(measured) +
                                      " terms FAIL the limits: the material does not represent the data there").c_str()
                                   : "every term fits its validation data within the limits");
    std::printf("  quadratic expansion error E (Eq. 4) = %s J/m^2 (measures smoothness, not fit); worst bake "
                "deviation %.2e of a term's range\n", E.c_str(), worst);
    {
      // Is the material's rest stress free and stable? (bake/rest_check.hpp; the fit limits
      // above are relative to whole ranges and do not see the small strains near rest.)
      std::string missing;
      const BakedMaterial mat = make_baked_material(read_baked(baked), baked, &missing);
      std::printf("  %s%s\n", check_rest(mat).summary().c_str(), rve_rest_note(read_dataset(ds).rest_hessian).c_str());
    }
    for (const auto& [name, secs] : times) std::printf("  %s: %s\n", name.c_str(), format_seconds(secs).c_str());
    std::printf("  total %s\n", format_seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - t_all).count()).c_str());
    std::printf("  metrics: %s\n", errors.c_str());
    if (!o->no_plot) std::printf("  pictures: %s\n", (run / "plots").string().c_str());
  });
}

}  // namespace yarnhom::tools
