// yarnhom fit-splines: the HYLC-style baseline, every term of a dataset fitted by a Hermite
// spline with few knots, written as a baked file (bake/spline_fit.hpp, docs/accuracy.md).
#include <chrono>
#include <cstdio>
#include <memory>

#include "bake/spline_fit.hpp"
#include "core/baked.hpp"
#include "core/dataset.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"

namespace yarnhom::tools {

void register_fit_splines(CLI::App& app) {
  struct Opts {
    std::string data, out;
    SplineFitOptions fit;
    bool no_monotone = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "fit-splines",
      "Fit the HYLC-style spline baseline (Sperl et al. 2020) to a dataset: per term a cubic "
      "Hermite spline with few knots (1D) or a bicubic Hermite patch on a coarse grid (2D), by "
      "least squares on the energies and their gradients with a small curvature penalty; 1D "
      "terms monotone away from their minimum, 2D terms zero on the axes; linear extrapolation "
      "outside the knots. Writes a baked file that sim, eval and export-hylc read like a baked "
      "network (docs/accuracy.md).");
  cmd->add_option("DATASET", o->data, "Dataset file (HDF5) written by produce or synth")->required()->check(existing_regular_file());
  cmd->add_option("-o,--output", o->out, "Baked file to write (HDF5, written atomically)")->required();
  cmd->add_option("--knots1d", o->fit.knots1d, "Knots of a 1D spline (HYLC: 11)")->check(CLI::Range(3, 1000))->capture_default_str();
  cmd->add_option("--knots2d", o->fit.knots2d, "Knots per axis of a 2D spline (HYLC: 8 to 10)")->check(CLI::Range(3, 200))->capture_default_str();
  cmd->add_option("--smoothing", o->fit.smoothing,
                  "Weight of the curvature penalty (per sample, energies over their standard "
                  "deviation, strains over the box width)")
      ->check(finite_non_negative())
      ->capture_default_str();
  cmd->add_option("--gradient-weight", o->fit.gradient_weight,
                  "Weight of the gradient residuals against the energy residuals (same units)")
      ->check(finite_non_negative())
      ->capture_default_str();
  cmd->add_flag("--no-monotone", o->no_monotone, "Do not constrain 1D terms to be monotone away from their minimum");
  cmd->callback([o] {
    const auto t0 = std::chrono::steady_clock::now();
    o->fit.monotone = !o->no_monotone;
    prepare_output(o->out, {o->data});
    const Dataset ds = read_dataset(o->data);
    std::vector<SplineFitReport> reports;
    const BakedModel m = fit_splines(ds, o->data, o->fit, &reports);
    write_baked(o->out, m);
    std::printf("term  knots   energy RMSE/range  grad err/mean  monotone (minimum knot, active constraints)\n");
    for (const SplineFitReport& r : reports) {
      std::string knots = std::to_string(r.knots[0]) + (r.knots[1] ? "x" + std::to_string(r.knots[1]) : "");
      std::string mono = r.minimum_knot >= 0 ? "knot " + std::to_string(r.minimum_knot) + ", " +
                                                   std::to_string(r.constraints_active) + " active"
                                             : "-";
      std::printf("%-5s %-7s %-18.3e %-14.3e %s\n", r.term.c_str(), knots.c_str(), r.energy_rmse_rel,
                  r.gradient_err_rel, mono.c_str());
    }
    std::printf("fitted %zu terms in %.2fs -> %s\n", m.tables.size(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), o->out.c_str());
  });
}

}  // namespace yarnhom::tools
