#pragma once
// Subcommand registration. Each tools/cmd_*.cpp defines one register_* function and adds it
// to command_registry() below; the subcommand's callback does the work and throws ExitCode to
// leave with a specific status (std::exception prints "yarnhom: error: ..." and exits 1).
#include <CLI/CLI.hpp>
#include <vector>

namespace yarnhom::tools {

struct ExitCode {
  int code;
};

void register_synth(CLI::App& app);
void register_train(CLI::App& app);  // train and train-all
void register_eval(CLI::App& app);
void register_bake(CLI::App& app);   // tools/cmd_bake.cpp
void register_error(CLI::App& app);  // tools/cmd_error.cpp
void register_plot(CLI::App& app);   // tools/cmd_plot.cpp
void register_pipeline(CLI::App& app);  // tools/cmd_pipeline.cpp
void register_rve(CLI::App& app);       // tools/cmd_rve.cpp
void register_produce(CLI::App& app);   // tools/cmd_produce.cpp
void register_fit_splines(CLI::App& app);  // tools/cmd_fit_splines.cpp
void register_accuracy(CLI::App& app);     // tools/cmd_accuracy.cpp
void register_study_accuracy(CLI::App& app);  // tools/cmd_study.cpp: study table5, bake-resolution, rve-size
void register_study_architectures(CLI::App& app);  // tools/cmd_study_architectures.cpp: study architectures
void register_sim(CLI::App& app);       // tools/cmd_sim.cpp
void register_export_hylc(CLI::App& app);  // tools/cmd_export_hylc.cpp
void register_strip(CLI::App& app);     // tools/cmd_strip.cpp

inline std::vector<void (*)(CLI::App&)> command_registry() {
  return {register_synth,       register_train,        register_eval,         register_bake,
          register_error,       register_plot,         register_pipeline,     register_rve,
          register_produce,     register_sim,          register_export_hylc,  register_fit_splines,
          register_accuracy,    register_study_accuracy, register_study_architectures, register_strip};
}

}  // namespace yarnhom::tools
