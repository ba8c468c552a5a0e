// yarnhom pipeline: produce -> train-all -> bake -> error -> plot in one command, each stage
// skipped when up to date (pipeline/run_pipeline.hpp).
#include "pipeline/run_pipeline.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

void register_pipeline(CLI::App& app) {
  auto [cmd, o] = add_command<pipeline::PipelineOptions>(app, "pipeline");
  add_pattern_argument(cmd, o->pattern, "A pattern for produce (.pyp file or built-in name), or 'synthetic'");
  add_output_option(cmd, o->run, "Run folder (created)");
  add_preset_option(cmd, o->preset,
                    "Sampling density: quick or paper (tiny: produce's 5 / 3 x 3 points, for tests; not for 'synthetic')", true);
  cmd->add_option("--backend", o->backend, "Training backend: cpu or cuda")->check(backend_validator())->capture_default_str();
  add_threads_option(cmd, o->threads, "CPU threads for training (0: all cores)")->capture_default_str();
  add_epochs_option(cmd, o->epochs, "Epochs per network (0: the paper's 500)");
  cmd->add_option("--recipe", o->recipe, "Training recipe, as train-all's --recipe: default, paper or improved")
      ->check(CLI::IsMember({"default", "paper", "improved"}))
      ->capture_default_str();
  add_force_flag(cmd, o->force);
  cmd->add_flag("--no-plot", o->no_plot, "Skip the plot stage (no PNGs; the metrics are in errors.txt)");
  CLI::App* root = &app;
  cmd->callback([o, root] { exit_with(pipeline::run_pipeline(*o, command_names(*root))); });
}

}  // namespace yarnhom::tools
