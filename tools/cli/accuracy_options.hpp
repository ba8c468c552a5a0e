#pragma once
// The accuracy test's options (pipeline/accuracy_run.hpp), as `accuracy` and the accuracy studies
// (`study table5`, `bake-resolution`, `rve-size`, `strip-width`) declare them.
#include <sstream>
#include <string>

#include "pipeline/accuracy_run.hpp"
#include "tools/cli/cli_util.hpp"
#include "tools/cli/stage_checks.hpp"

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
  add_preset_option(cmd, a.preset, "produce's sampling preset: quick or paper (tiny: 5 / 3 x 3 points, for tests)", true);
  if (!help.size.empty()) cmd->add_option("--size", a.size, help.size)->capture_default_str();
  cmd->add_option("--stretch", a.stretch, help.stretch)->capture_default_str();
  if (help.reuse) add_reuse_options(cmd, a.dataset, a.baked);
  add_epochs_option(cmd, a.epochs, "train-all's epochs per network (0: its default)");
  add_threads_option(cmd, a.threads,
                     "Threads for produce and train-all (0: all cores). Under mpirun -np N (the test's pieces run on "
                     "the ranks, docs/produce.md) each rank's stages take by default the node's cores / its ranks "
                     "(at most the rank's own CPUs), through OMP_NUM_THREADS unless that is set")
      ->capture_default_str();
  cmd->add_option("--spacing", a.spacing, "Surface sampling of the Hausdorff distance, metres")
      ->check(finite_positive())
      ->capture_default_str();
  cmd->add_option("--strip-args", a.strip_args, help.strip_args);
  cmd->add_option("--sim-args", a.sim_args, help.sim_args);
  add_force_flag(cmd, a.force);
  cmd->footer(
      "On a cluster: mpirun -np N yarnhom " + std::string(cmd->get_parent() && cmd->get_parent()->get_name() == "study" ? "study " : "") +
      cmd->get_name() +
      " ... (a build with MPI) runs the independent stages (yarn strips, datasets, training, continuum strips) on the "
      "ranks, rank 0 handing them out, then writes the same files as one process; each rank's stage lines go to "
      "OUT/logs/rank-R.log; a rerun with any number of ranks resumes (docs/produce.md, \"The studies on a cluster\").");
}

// Before the first stage (issue 32): the test's own options (--stretch from 1.0, --dataset a
// dataset, --baked a baked file) and, per pattern, direction and size the run will use, the
// strip and sim stretch command lines it will start, with --strip-args and --sim-args, checked
// as those commands check them. Each message names the options and values.
inline void check_accuracy_run(const pipeline::AccuracyOptions& a, const std::vector<std::string>& patterns,
                               const std::vector<std::string>& directions, const std::vector<std::string>& sizes) {
  pipeline::check_accuracy_options(a);
  auto split = [](const std::string& s) {
    std::vector<std::string> out;
    std::string cur;
    for (char c : s + " ")
      if (c != ' ') cur += c;
      else if (!cur.empty()) out.push_back(std::exchange(cur, ""));
    return out;
  };
  for (const std::string& size : sizes)
    for (const std::string& dir : directions) {
      const std::string common = " --size " + size + " --direction " + dir + " --stretch " + a.stretch;
      double clamp = 0.005;
      for (const std::string& pattern : patterns) {
        std::vector<std::string> strip = {"strip", pattern, "--size", size, "--direction", dir, "--stretch", a.stretch, "-o", "STRIP"};
        for (const std::string& x : split(a.strip_args)) strip.push_back(x);
        try {
          clamp = check_strip_stage(strip);
        } catch (const std::exception& e) {
          throw std::invalid_argument("the yarn strip stage would refuse its options (" + pattern + common +
                                      (a.strip_args.empty() ? "" : " --strip-args '" + a.strip_args + "'") + "): " + e.what());
        }
      }
      // The clamp band as the strip's settings.txt will give it (pipeline/accuracy_run.cpp).
      std::ostringstream band;
      band.precision(17);
      band << clamp;
      std::vector<std::string> sim = {"sim", "stretch", "-o", "SIM", "--direction", dir, "--size", size,
                                      "--stretch", a.stretch, "--clamp", band.str(), "-q"};
      for (const std::string& x : split(a.sim_args)) sim.push_back(x);
      try {
        check_sim_stage(sim);
      } catch (const std::exception& e) {
        throw std::invalid_argument("the continuum strip stage (sim stretch) would refuse its options (" + common.substr(1) +
                                    (a.sim_args.empty() ? "" : " --sim-args '" + a.sim_args + "'") + "): " + e.what());
      }
    }
}

}  // namespace yarnhom::tools
