// yarnhom study architectures: supplement Table 3, the paper's four networks trained on one term
// side by side (pipeline/study.hpp).
#include "pipeline/study.hpp"
#include "tools/cli/cli_util.hpp"
#include "train/recipe.hpp"

namespace yarnhom::tools {

void register_study_architectures(CLI::App& app) {
  CLI::App* study = study_group(app, "Studies that reproduce the supplement's tables (docs/accuracy.md, docs/training.md)");
  auto [cmd, o] = add_command<pipeline::ArchitecturesOptions>(*study, "architectures");
  cmd->add_option("DATASET", o->dataset, "Dataset file (HDF5) written by 'produce' or 'synth'")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--term", o->term, "The term to train, e.g. 0 or 02 (the paper's table: basket term 0)")
      ->capture_default_str();
  cmd->add_option("-o,--output", o->out, "Folder for architectures.csv and architectures.png (created)")
      ->capture_default_str();
  cmd->add_option("--recipe", o->recipe, "Training recipe, as train-all's (the paper's table used the paper's)")
      ->check(CLI::IsMember(recipe_names()))
      ->capture_default_str();
  cmd->add_option("--epochs", o->epochs, "Epochs (0: the recipe's, 500)")->check(CLI::NonNegativeNumber)->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of split, initialization, shuffling")->capture_default_str();
  cmd->add_option("--threads", o->threads,
                  "CPU threads per network (1: each network's time is one core's, comparable across runs)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--backend", o->backend, "Compute backend for the epochs: cpu, or cuda when built with CUDA")
      ->capture_default_str();
  cmd->add_flag("--no-plot", o->no_plot, "Do not draw the PNG (the CSV is written anyway)");
  cmd->callback([o] { exit_with(pipeline::run_study_architectures(*o)); });
}

}  // namespace yarnhom::tools
