// yarnhom accuracy: one pattern, one direction, end to end (supplement section 4.2, Table 5;
// pipeline/accuracy_run.hpp).
#include "pipeline/accuracy_run.hpp"
#include "tools/cli/accuracy_options.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

void register_accuracy(CLI::App& app) {
  auto [cmd, o] = add_command<pipeline::AccuracyOptions>(app, "accuracy");
  add_pattern_argument(cmd, o->pattern, "Pattern (.pyp file or built-in name), as produce and strip take it");
  add_direction_option(cmd, o->direction, "Stretch direction: course (x) or wale (y)")->required();
  add_output_option(cmd, o->out, "Output folder (created)");
  AccuracyOptionHelp help;
  help.size = "Strip width,length in metres, the yarn strip's and the continuum strip's (the paper: 0.05,0.10)";
  help.stretch = "Stretch ratios 1.0:LAST:STEP, both strips (the paper: 1.0:1.7:0.05, 15 tests)";
  help.reuse = true;
  help.strip_args = "Extra arguments for strip (one string, split at spaces)";
  help.sim_args = "Extra arguments for sim stretch (one string, split at spaces)";
  add_accuracy_options(cmd, *o, help);
  CLI::App* root = &app;
  cmd->callback([o, root] {
    check_accuracy_run(*o, {o->pattern}, {o->direction}, {o->size});  // before the first stage
    pipeline::run_accuracy_command(*o, command_names(*root));
  });
}

}  // namespace yarnhom::tools
