// yarnhom rve: the yarn RVE of a pattern at one macroscopic strain (yarn/rve/rve_run.hpp).
#include "tools/cli/cli_util.hpp"
#include "yarn/rve/rve_run.hpp"

namespace yarnhom::tools {

namespace {

// What is printed and checked.
void add_report_options(CLI::App* cmd, yarn::RveRunOptions& o) {
  cmd->add_flag("--json", o.json,
                "Print one JSON object: psi, grad, iterations, residual, seconds, converged, psi0, rest_grad, "
                "lattice_original and lattice_relaxed (lattice vectors, m), reference_strain, areal_density, certificate_valid, min_separation and d_min (in yarn diameters 2r), barrier_energy, ...");
  cmd->add_option("--certify", o.certify,
                  "Re-check the topology certificate of a state file written by --out: every configuration of its "
                  "recorded path, from the pattern's own geometry, and every straight move between them must keep "
                  "all yarn segment pairs above d_min (CCD). Exit status 3 when it does not hold")
      ->check(existing_regular_file());
  cmd->add_flag("--no-ccd", o.no_ccd,
                "Do not shorten Newton steps by collision detection (for comparison only: yarns may pass through "
                "each other; the certificate then says so)");
  add_verbose_flag(cmd, o.verbose);
  cmd->add_flag("--rest-hessian", o.rest_hessian,
                "Also measure d2Psi/ds2 at s = 0 (6 x 6, central differences of dPsi/ds from 12 small solves around "
                "the relaxed rest; what produce stores in the dataset and the training holds the networks to, "
                "yarn/rve/rest_hessian.hpp) and say whether the rest is stable");
}

// Where the solve starts: a state file, or the pattern relaxed at rest (its period too, unless
// --fixed-period), tiled.
void add_reference_options(CLI::App* cmd, yarn::RveRunOptions& o) {
  cmd->add_option("--start", o.start,
                  "Start from this state file (warm start) instead of the relaxed rest state; the strain is then "
                  "measured from the reference tile the file was solved in")
      ->check(existing_regular_file());
  cmd->add_flag("--fixed-period", o.fixed_period,
                "Relax the yarns at the pattern's own period only (the tile stays pre-stressed: dPsi/ds(0) != 0); "
                "default: the period relaxes too and s = 0 is the stress-free tile");
  cmd->add_option("--tile", o.tile,
                  "NX,NY: solve the pattern tiled NX x NY times, from its relaxed rest repeated (a larger RVE of "
                  "the same material: in-plane strains give the same Psi, curvature shows the map's tile-size "
                  "dependence; docs/rve.md section 2)");
}

// The Newton solves: the rest relaxation and the one at the strain.
void add_solve_options(CLI::App* cmd, yarn::RveRunOptions& o) {
  cmd->add_option("--tolerance", o.tolerance, "Relative residual to converge to, in (0, 0.1] (default 1e-10)")
      ->check(finite_range(1e-300, 0.1, "a relative residual in (0, 0.1]"));
  cmd->add_option("--max-iterations", o.max_iterations,
                  "Newton iterations at most of each solve: the rest relaxation's and the one at the strain "
                  "(default 500)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--time-limit", o.time_limit,
                  "Wall-clock limit in seconds of the rest relaxation (all of it) and of the solve at the strain; "
                  "0: none (default 300)")
      ->check(finite_non_negative());
}

}  // namespace

void register_rve(CLI::App& app) {
  auto [cmd, o] = add_command<yarn::RveRunOptions>(app, "rve");
  add_pattern_argument(cmd, o->pattern);
  cmd->add_option("--strain", o->strain, "s_x,s_a,s_y,II_x,II_a,II_y (II in 1/m; default 0,0,0,0,0,0)");
  add_yarn_material_option(cmd, o->material);
  cmd->add_option("--out", o->out, "Write the equilibrium state (HDF5)");
  cmd->add_option("--obj", o->obj, "Write a tube mesh of the yarns (OBJ)");
  cmd->add_option("--pattern-out", o->pattern_out,
                  "Write the pattern relaxed at rest as .pyp (its geometry is then an equilibrium)");
  cmd->add_option("--energy-map", o->energy_map,
                  "Write where the energy sits at the solved strain: one tab-separated row per vertex (yarn, "
                  "position, stretch, bend, twist, contact, barrier in J/m^2, curvature now and at rest; docs/rve.md)");
  add_reference_options(cmd, *o);
  add_solve_options(cmd, *o);
  add_report_options(cmd, *o);
  cmd->callback([o] { exit_with(yarn::run_rve(*o)); });
}

}  // namespace yarnhom::tools
