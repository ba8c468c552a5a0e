// yarnhom synth: a dataset in the spec's format from the analytic energy of docs/synthetic.md
// (produce/synthetic_run.hpp).
#include "produce/synthetic_run.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

void register_synth(CLI::App& app) {
  struct Opts {
    std::string out, preset = "quick";
  };
  auto [cmd, o] = add_command<Opts>(app, "synth");
  add_output_option(cmd, o->out, "Dataset file to write (HDF5); written atomically");
  cmd->add_option("--preset", o->preset,
                  "Sampling density: 'quick' (21 points per 1D term, 9 x 9 grid per 2D term) or "
                  "'paper' (100 points, 31 x 31 grid)")
      ->check(CLI::IsMember({"quick", "paper"}))
      ->capture_default_str();
  cmd->callback([o] { run_synth(o->out, o->preset); });
}

}  // namespace yarnhom::tools
