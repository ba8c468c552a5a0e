#pragma once
// The accuracy test of supplement section 4.2 (docs/accuracy.md), shared by `accuracy` and the
// `study` subcommands: dataset -> networks -> baked material, the spline baseline on the same
// data, the yarn-level strip and the continuum strip for both materials under the same clamps,
// and per stretch the stress difference and the Hausdorff distance. Every stage is a subcommand
// of this program run as a child process with its log, cached and resumable
// (pipeline/stage_runner.hpp); the metrics are computed here.
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "accuracy/strip_metrics.hpp"

namespace yarnhom::pipeline {

struct AccuracyOptions {
  std::string pattern, direction, out;
  std::string preset = "quick";
  std::string size = "0.05,0.10";
  std::string stretch = "1.0:1.7:0.05";
  std::string dataset, baked;  // reuse instead of producing / training + baking
  std::string materials_dir;   // where dataset, model and baked files go (default: out)
  std::string strip_dir;       // where the yarn strip goes (default: out/strip), to share it
  int epochs = 0, threads = 0;
  double spacing = 5e-4;       // Hausdorff surface sampling, metres
  std::string strip_args, sim_args;
  bool force = false;
  bool spline = true;          // also the spline baseline
};

struct MaterialResult {
  std::string name;  // "neural" or "spline"
  std::string baked;
  std::vector<StepMetrics> steps;  // the tests its continuum strip reached (all, unless it failed)
  AccuracySummary summary;         // over those tests
  std::string failure;             // the spline baseline's sim stage failed: why (its steps stop there)
  std::string box_note;            // where its strip's middle reached the data boxes (accuracy/box_reach.hpp)
};

struct AccuracyResult {
  std::vector<double> stretch, n_yarn;
  bool n_yarn_per_load_width = true;  // false: the strip's force.csv predates the load width (nominal width)
  std::vector<MaterialResult> materials;
  std::vector<std::pair<std::string, double>> stage_seconds;  // the stages that ran
  double seconds = 0;
};

// The test's own options checked before any stage: --stretch a range from the relaxed 1.0,
// --dataset a dataset, --baked a baked file (a dataset given as --baked used to run for 20 s
// first). Throws std::invalid_argument naming the option and the value. The strip and sim
// stages' options are checked by the commands' own parsers (tools/cli/accuracy_options.hpp).
void check_accuracy_options(const AccuracyOptions& o);

// Runs (or resumes) the test into o.out: accuracy.csv and accuracy.md (its total time counted
// from t0).
AccuracyResult run_accuracy(const AccuracyOptions& o, std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now());
std::string accuracy_report_text(const AccuracyResult& r, const AccuracyOptions& o);

// `yarnhom accuracy`: refuses a build without the commands the test needs (`commands`: those
// this program has), runs the test and prints the report.
void run_accuracy_command(const AccuracyOptions& o, const std::vector<std::string>& commands);

// The stages' argument lists shared with the studies: produce's and train-all's (threads and
// epochs 0: the subcommand's default).
std::vector<std::string> produce_stage_args(const std::string& pattern, const std::string& dataset,
                                            const std::string& preset, int threads);
std::vector<std::string> train_stage_args(const std::string& dataset, const std::string& model, int threads, int epochs);

// The test's pieces as tasks for the ranks of an mpirun (pipeline/rank_tasks.hpp): the yarn
// strip; produce; train-all and bake; fit-splines; each continuum strip once its material and
// the yarn strip are done. Tasks the study shares (the same stage record) are added once.
// `after`: tasks that make the dataset or baked file the options name. `label` begins each
// task's progress line.
class RankTasks;
void add_accuracy_tasks(RankTasks& g, const AccuracyOptions& o, const std::string& label, const std::vector<int>& after = {});
// A produce task's weight among the tasks (an n x n patch's: `tiles` = n).
double produce_task_weight(const std::string& preset, int tiles = 1);

}  // namespace yarnhom::pipeline
