// yarnhom eval: a trained term's energy and derivatives at given strains, as CSV
// (bake/eval_run.hpp).
#include "bake/eval_run.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

void register_eval(CLI::App& app) {
  auto [cmd, o] = add_command<EvalOptions>(app, "eval");
  cmd->add_option("MODEL", o->model, "Model file (HDF5) written by train-all, or baked file written by bake")->required()->check(existing_regular_file());
  cmd->add_option("--term", o->term, "The term, e.g. 02")->required()->check(term_list_validator(true));
  cmd->add_option("--at", o->at, "A strain point: d comma-separated values (repeatable)");
  cmd->add_option("--points", o->points, "CSV file of strain points, one per line")->check(existing_regular_file());
  cmd->callback([o] { run_eval(*o); });
}

}  // namespace yarnhom::tools
