// yarnhom bake: trained networks -> Hermite tables with the safeguard (spec section 8;
// bake/bake_run.hpp).
#include "bake/bake_run.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

void register_bake(CLI::App& app) {
  auto [cmd, o] = add_command<BakeRunOptions>(app, "bake");
  cmd->add_option("MODEL", o->model, "Model file (HDF5) written by train-all")->required()->check(existing_regular_file());
  add_output_option(cmd, o->out, "Baked file to write (HDF5, written atomically)");
  cmd->add_option("--res1d", o->res1d, "Knots of a 1D table (the paper: 200)")->check(CLI::Range(2, 1000000))->capture_default_str();
  cmd->add_option("--res2d", o->res2d, "Knots per axis of a 2D table (the paper: 100)")->check(CLI::Range(2, 10000))->capture_default_str();
  cmd->add_option("--data", o->data,
                  "Dataset whose Psi0 (rest energy) to store for the full material; default: the "
                  "model's own dataset when it can be found")
      ->check(existing_regular_file());
  cmd->add_flag("--no-check", o->no_check, "Skip measuring each table against its network");
  cmd->callback([o] { run_bake(*o); });
}

}  // namespace yarnhom::tools
