#pragma once
// Subcommand registration. Each tools/cli/cmd_*.cpp defines one register_* function and adds it
// to command_registry() below: it declares the command's options into an options struct, and
// its callback calls one library function (pipeline/ for what chains subcommands or runs
// Python, the concept's room otherwise). A callback leaves with a specific status by throwing
// ExitCode (exit_with); std::exception prints "yarnhom: error: ..." and exits 1.
#include <CLI/CLI.hpp>
#include <vector>

namespace yarnhom::tools {

struct ExitCode {
  int code;
};

// Leaves the program with `status` unless it is 0 (a library function's exit status).
inline void exit_with(int status) {
  if (status != 0) throw ExitCode{status};
}

void register_synth(CLI::App& app);
void register_train(CLI::App& app);  // train and train-all
void register_eval(CLI::App& app);
void register_bake(CLI::App& app);   // tools/cli/cmd_bake.cpp
void register_error(CLI::App& app);  // tools/cli/cmd_error.cpp
void register_plot(CLI::App& app);   // tools/cli/cmd_plot.cpp
void register_pipeline(CLI::App& app);  // tools/cli/cmd_pipeline.cpp
void register_rve(CLI::App& app);       // tools/cli/cmd_rve.cpp
void register_produce(CLI::App& app);   // tools/cli/cmd_produce.cpp
void register_fit_splines(CLI::App& app);  // tools/cli/cmd_fit_splines.cpp
void register_accuracy(CLI::App& app);     // tools/cli/cmd_accuracy.cpp
void register_study_accuracy(CLI::App& app);  // tools/cli/cmd_study.cpp: study table5, bake-resolution, rve-size, strip-width
void register_study_architectures(CLI::App& app);  // tools/cli/cmd_study_architectures.cpp: study architectures
void register_sim(CLI::App& app);       // tools/cli/cmd_sim.cpp
void register_export_hylc(CLI::App& app);  // tools/cli/cmd_export_hylc.cpp
void register_strip(CLI::App& app);     // tools/cli/cmd_strip.cpp

// The `study` group, shared by cmd_study.cpp and cmd_study_architectures.cpp: whichever registers
// first creates it.
inline CLI::App* study_group(CLI::App& app, const char* help) {
  for (CLI::App* s : app.get_subcommands([](CLI::App*) { return true; }))
    if (s->get_name() == "study") return s;
  CLI::App* g = app.add_subcommand("study", help);
  g->require_subcommand(1);
  return g;
}

inline std::vector<void (*)(CLI::App&)> command_registry() {
  return {register_synth,       register_train,        register_eval,         register_bake,
          register_error,       register_plot,         register_pipeline,     register_rve,
          register_produce,     register_sim,          register_export_hylc,  register_fit_splines,
          register_accuracy,    register_study_accuracy, register_study_architectures, register_strip};
}

}  // namespace yarnhom::tools
