#pragma once
// The accuracy test's options (pipeline/accuracy_run.hpp), as `accuracy` and the accuracy studies
// (`study table5`, `bake-resolution`, `rve-size`, `strip-width`) declare them.
#include <string>

#include "pipeline/accuracy_run.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

struct AccuracyOptionHelp {
  std::string size = "Strip width,length in metres";  // "": no --size (the command sets the size)
  std::string stretch = "Stretch ratios first:last:step";
  bool reuse = false;  // also --dataset and --baked
  std::string strip_args = "Extra arguments for strip";
  std::string sim_args = "Extra arguments for sim stretch";
};

inline void add_reuse_options(CLI::App* cmd, std::string& dataset, std::string& baked) {
  cmd->add_option("--dataset", dataset, "Reuse this dataset instead of producing one")->check(existing_regular_file());
  cmd->add_option("--baked", baked, "Reuse this baked neural material instead of training and baking")
      ->check(existing_regular_file());
}

// --preset, [--size,] --stretch, [--dataset, --baked,] --epochs, --threads, --spacing, --strip-args,
// --sim-args, --force.
inline void add_accuracy_options(CLI::App* cmd, pipeline::AccuracyOptions& a, const AccuracyOptionHelp& help = {}) {
  add_preset_option(cmd, a.preset, "produce's sampling preset: quick or paper");
  if (!help.size.empty()) cmd->add_option("--size", a.size, help.size)->capture_default_str();
  cmd->add_option("--stretch", a.stretch, help.stretch)->capture_default_str();
  if (help.reuse) add_reuse_options(cmd, a.dataset, a.baked);
  add_epochs_option(cmd, a.epochs, "train-all's epochs per network (0: its default)");
  add_threads_option(cmd, a.threads, "Threads for produce and train-all (0: all cores)")->capture_default_str();
  cmd->add_option("--spacing", a.spacing, "Surface sampling of the Hausdorff distance, metres")
      ->check(finite_positive())
      ->capture_default_str();
  cmd->add_option("--strip-args", a.strip_args, help.strip_args);
  cmd->add_option("--sim-args", a.sim_args, help.sim_args);
  add_force_flag(cmd, a.force);
}

}  // namespace yarnhom::tools
