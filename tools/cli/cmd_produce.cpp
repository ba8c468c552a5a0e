// yarnhom produce: the yarn RVE dataset of a pattern (produce/produce_run.hpp).
#include "produce/produce_run.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

namespace {

// The branch pass and the warm starts (docs/produce.md).
void add_branch_options(CLI::App* cmd, yarn::ProduceRunOptions& o) {
  cmd->add_option("--branch-rounds", o.branch_rounds,
                  "Rounds of the branch pass, 0..200 (default 12; 0: off): after every node is solved, both nodes "
                  "of each grid edge whose energies and gradients disagree are solved again from the other's "
                  "equilibrium, and a node keeps the lower-energy branch, which its neighbours then try in the next "
                  "round; until nothing moves. The data then lie on the lowest branch their neighbours reach "
                  "(docs/produce.md). Needs warm starts")
      ->check(CLI::Range(0, 200));
  cmd->add_option("--branch-tolerance", o.branch_tolerance,
                  "Trapezoid-rule mismatch along a grid edge, relative to the term's typical edge change, above "
                  "which the edge counts as two branches (default 0.05)")
      ->check(finite_range(1e-6, 10.0, "a relative mismatch in [1e-6, 10]"));
  cmd->add_flag("--no-warm-start", o.no_warm, "Solve every node from the rest state (for comparison)");
  cmd->add_flag("--no-predictor", o.no_predictor,
                "Warm start from the parent's solution as it is (supplement Eq. 2-3 only), without our "
                "first-order continuation step along the equilibrium's sensitivity (docs/produce.md)");
}

// The RVE: its rest, its size, its yarn, its sampling boxes.
void add_rve_options(CLI::App* cmd, yarn::ProduceRunOptions& o) {
  cmd->add_flag("--fixed-period", o.fixed_period,
                "Keep the pattern's own tile period at s = 0 (a pre-stressed rest, as before the stress-free "
                "rest; for comparison). Default: the period relaxes and s = 0 is the stress-free tile");
  cmd->add_option("--tile", o.tile,
                  "NX,NY: the RVE is the pattern's relaxed tile repeated NX x NY times (default 1,1). Psi is per "
                  "area, so a patch samples the same material, but lets neighbouring tiles buckle and slide "
                  "differently, which one tile cannot (docs/produce.md, \"One tile can be too small an RVE\": the "
                  "cartridge belt rib's course; the shear couplings' data). Costs 5-7x the solves' CPU time of 1,1 at 2,2 (docs/benchmarks.md, \"Patch RVEs\")");
  add_yarn_material_option(cmd, o.material);
  cmd->add_option("--ranges", o.ranges, "Sampling boxes: 'index lower upper' lines")->check(existing_regular_file());
}

}  // namespace

void register_produce(CLI::App& app) {
  auto [cmd, o] = add_command<yarn::ProduceRunOptions>(app, "produce");
  add_pattern_argument(cmd, o->pattern);
  add_output_option(cmd, o->out, "Dataset file to write (HDF5)", "-o,--out");
  cmd->add_option("--preset", o->preset, "quick (21 points / 9 x 9), paper (101 / 31 x 31) or tiny (5 / 3 x 3, for tests)")
      ->check(CLI::IsMember({"quick", "paper", "tiny"}));
  cmd->add_option("--terms", o->terms, "Terms to produce, e.g. 0,02 (default all)")->check(term_list_validator());
  add_threads_option(cmd, o->threads, "Sectors solved in parallel (0 or absent: all cores, or OMP_NUM_THREADS where set; under mpirun: threads per rank, default 1)");
  cmd->add_option("--sectors", o->sectors, "Sectors per 2D term, 1..64 (default 8)")->check(CLI::Range(1, 64));
  cmd->add_option("--rest-time-limit", o->rest_time_limit,
                  "Wall-clock limit of the rest relaxation in seconds, 0: none (default 300; the largest "
                  "paper pattern relaxes in a few seconds)")
      ->check(finite_non_negative());
  add_branch_options(cmd, *o);
  add_rve_options(cmd, *o);
  cmd->callback([o] { exit_with(yarn::run_produce(*o)); });
}

}  // namespace yarnhom::tools
