#pragma once
// `yarnhom pipeline`: produce -> train-all -> bake -> error -> plot in one command, each stage
// skipped when its output is already there, newer than its input and made with the same
// settings (pipeline/pipeline_stage.hpp), so a rerun after an interruption continues.
//
// Each stage runs as this same program with the stage's subcommand, in a child process, with its
// output in RUN_DIR/logs/<stage>.log: the stages stay exactly the commands a user can run by
// hand, and one failing stage cannot leave the pipeline in a half state (outputs are atomic).
// A stage dies with the pipeline (pipeline/child_process.hpp): killing the pipeline, even with
// SIGKILL, never leaves a stage running that would race a rerun.
//
// PATTERN "synthetic" uses `synth` (the analytic stand-in, docs/synthetic.md). Any other PATTERN
// (a .pyp file or a built-in pattern name) goes to the `produce` subcommand (the yarn RVE
// producer); the pipeline uses it when this build has it and says so when it does not.
#include <string>
#include <vector>

namespace yarnhom::pipeline {

struct PipelineOptions {
  std::string pattern, run, preset = "quick", backend = "cpu", recipe = "default";
  int threads = 0, epochs = 0;
  bool force = false;
  bool no_plot = false;
};

// Runs the stages and prints the report. `commands`: the subcommands this program has. Returns
// the exit status: 0, or 1 when a stage failed (the plot stage's failure is reported, not fatal).
int run_pipeline(const PipelineOptions& o, const std::vector<std::string>& commands);

}  // namespace yarnhom::pipeline
