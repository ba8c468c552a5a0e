// yarnhom plot RUN_DIR: the pictures of a run (supplement Fig. 1, 3, 4 and 1D fits;
// pipeline/plot_run.hpp).
#include "pipeline/plot_run.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

void register_plot(CLI::App& app) {
  auto [cmd, o] = add_command<pipeline::PlotOptions>(app, "plot");
  cmd->add_option("RUN_DIR", o->run, "Run folder holding model.h5, baked.h5 and dataset.h5 (any may be missing)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--model", o->model, "Model file (default RUN_DIR/model.h5)")->check(existing_regular_file());
  cmd->add_option("--baked", o->baked, "Baked file (default RUN_DIR/baked.h5; baked in memory from the model if absent)")
      ->check(existing_regular_file());
  cmd->add_option("--data", o->data, "Dataset (default RUN_DIR/dataset.h5)")->check(existing_regular_file());
  cmd->add_option("-o,--output", o->out, "Folder for the PNGs (default RUN_DIR/plots)");
  cmd->callback([o] { exit_with(pipeline::run_plot(*o)); });
}

}  // namespace yarnhom::tools
