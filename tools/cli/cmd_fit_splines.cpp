// yarnhom fit-splines: the HYLC-style baseline fitted to a dataset, written as a baked file
// (accuracy/fit_splines_run.hpp).
#include "accuracy/fit_splines_run.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

void register_fit_splines(CLI::App& app) {
  auto [cmd, o] = add_command<FitSplinesOptions>(app, "fit-splines");
  cmd->add_option("DATASET", o->data, "Dataset file (HDF5) written by produce or synth")->required()->check(existing_regular_file());
  add_output_option(cmd, o->out, "Baked file to write (HDF5, written atomically)");
  cmd->add_option("--knots1d", o->fit.knots1d, "Knots of a 1D spline (HYLC: 11)")->check(CLI::Range(3, 1000))->capture_default_str();
  cmd->add_option("--knots2d", o->fit.knots2d, "Knots per axis of a 2D spline (HYLC: 8 to 10)")->check(CLI::Range(3, 200))->capture_default_str();
  cmd->add_option("--smoothing", o->fit.smoothing,
                  "Weight of the curvature penalty (per sample, energies over their standard "
                  "deviation, strains over the box width), in [0, 1e6]")
      ->check(finite_range(0, 1e6, "in [0, 1e6]"))
      ->capture_default_str();
  cmd->add_option("--gradient-weight", o->fit.gradient_weight,
                  "Weight of the gradient residuals against the energy residuals (same units), in [0, 1e6]")
      ->check(finite_range(0, 1e6, "in [0, 1e6]"))
      ->capture_default_str();
  cmd->add_flag("--no-monotone", o->no_monotone, "Do not constrain 1D terms to be monotone away from their minimum");
  cmd->callback([o] { run_fit_splines(*o); });
}

}  // namespace yarnhom::tools
