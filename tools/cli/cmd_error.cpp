// yarnhom error: the metrics of spec section 9 for a model or a baked file
// (accuracy/error_report.hpp).
#include "accuracy/error_report.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

void register_error(CLI::App& app) {
  auto [cmd, o] = add_command<ErrorReportOptions>(app, "error");
  cmd->add_option("FILE", o->file, "Model file (train-all) or baked file (bake)")->required()->check(existing_regular_file());
  cmd->add_option("--data", o->data, "Dataset (default: the one the file names, if found)")->check(existing_regular_file());
  cmd->add_option("--model", o->model,
                  "For a baked file: the model to measure its deviation against (default: the one "
                  "it was baked from, if found)")
      ->check(existing_regular_file());
  cmd->add_option("--terms", o->terms, "Terms to measure, e.g. 0,02 (default all)")
      ->check(term_list_validator())
      ->capture_default_str();
  cmd->add_option("--samples", o->samples, "Samples per neighbourhood in Eq. 5 (a square in 2D)")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  cmd->add_flag("--compare", o->compare, "Also print the bake-resolution table (needs the model)");
  cmd->add_option("--csv", o->csv, "Also write the per-term rows to this CSV file (written atomically)");
  cmd->callback([o] { run_error_report(*o); });
}

}  // namespace yarnhom::tools
