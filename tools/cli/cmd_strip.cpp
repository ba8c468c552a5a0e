// yarnhom strip PATTERN -o DIR: a yarn-level fabric strip clamped and stretched quasi-statically,
// resumable per load step (yarn/strip/strip_run.hpp), and its pictures (pipeline/strip_command.hpp).
#include "pipeline/strip_command.hpp"
#include "tools/cli/cli_util.hpp"
#include "tools/cli/stage_checks.hpp"

namespace yarnhom::tools {

namespace {

// The solve of each load step, and the run.
void add_solve_options(CLI::App* cmd, pipeline::StripCommandOptions& o) {
  cmd->add_option("--newton", o.newton,
                  "Newton method of each load step: trust-region (default: Steihaug-CG on the exact Hessian, "
                  "preconditioned by the projected Hessian's Cholesky factor) or switched (line searches on the "
                  "projected or the exact Hessian: the first method, slower; docs/strip.md section 4)");
  cmd->add_flag("--no-bind-off", o.no_bind_off, "Knits: no boundary course above and below (the edges may unravel)");
  cmd->add_option("--material", o.material, "Material file: 'key = value' lines (docs/yarn_material.md)")->check(existing_regular_file());
  cmd->add_option("--tolerance", o.tolerance, "Relative residual each load step converges to (default 1e-10)")
      ->check(finite_range(1e-300, 0.1, "a relative residual in (0, 0.1]"));
  cmd->add_option("--max-iterations", o.max_iterations, "Newton iterations per load step at most (default 300)")
      ->check(CLI::Range(1, 1000000));
  add_threads_option(cmd, o.threads,
                     "Threads for the assembly (0 or absent: all cores); the BLAS under CHOLMOD runs on one unless "
                     "OPENBLAS_NUM_THREADS says otherwise");
  cmd->add_option("--rest-time-limit", o.rest_time_limit,
                  "Wall-clock limit of the tile's rest relaxation in seconds, 0: none (default 300; the paper's "
                  "patterns relax in seconds to a minute)")
      ->check(finite_non_negative());
  cmd->add_flag("--restart", o.restart, "Discard what the run folder holds and start again");
  cmd->add_flag("--no-plots", o.no_plots, "Write no PNGs");
  add_verbose_flag(cmd, o.verbose);
}

}  // namespace

namespace {

// strip's options into o.
CLI::App* declare_strip(CLI::App& app, const std::shared_ptr<pipeline::StripCommandOptions>& op) {
  CLI::App* cmd = app.add_subcommand("strip", command_help("strip"));
  pipeline::StripCommandOptions* o = op.get();
  add_pattern_argument(cmd, o->pattern);
  add_output_option(cmd, o->out, "Run folder (created; a rerun resumes it)");
  cmd->add_option("--size", o->size, "WIDTH,LENGTH of the strip in metres (default 0.05,0.10)");
  cmd->add_option("--direction", o->direction,
                  "course: the long axis (and the load) along the pattern's x, the course; wale: along y (default course)");
  cmd->add_option("--stretch", o->stretch,
                  "FROM:TO:STEP load steps as clamp separation / initial (default 1.0:1.7:0.05); the strip is always "
                  "relaxed at 1.0 first");
  cmd->add_option("--clamp", o->clamp, "Clamp band at each short end, metres (default 0.005): every vertex within it is held")
      ->check(finite_positive());
  cmd->add_option("--connector-scale", o->connector_scale, "Moduli of the boundary yarn relative to the yarn's, in (0, 1] (default 1/200, the supplement's). 1 gives "
                  "the selvedges the yarn's own stiffness, as in a knit where the yarn turns into the next course: our "
                  "joins are long, and at 1/200 the selvedges are nearly free (docs/accuracy.md, \"The boundary yarn's "
                  "stiffness\")")
      ->check(finite_range(1e-12, 1.0, "in (0, 1]"));
  add_solve_options(cmd, *o);
  return cmd;
}

}  // namespace

void register_strip(CLI::App& app) {
  auto o = std::make_shared<pipeline::StripCommandOptions>();
  CLI::App* cmd = declare_strip(app, o);
  cmd->callback([o] { exit_with(pipeline::run_strip_command(*o)); });
}

double check_strip_stage(const std::vector<std::string>& args) {
  CLI::App app;
  auto o = std::make_shared<pipeline::StripCommandOptions>();
  declare_strip(app, o)->callback([o] { yarn::check_strip_options(*o); });
  parse_stage(app, args);
  return o->clamp;
}

}  // namespace yarnhom::tools
