#pragma once
// The yarn RVE data producer (issue 4, spec sections 3-5): Psi(s) and dPsi/ds on each term's
// node grid, solved sector by sector in the order of supplement Algorithm 1 with warm starts,
// checkpointed as samples finish, assembled into the dataset that train-all reads.
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/dataset.hpp"
#include "core/terms.hpp"
#include "yarn/rve/newton.hpp"
#include "yarn/rve/rest.hpp"
#include "yarn/rve/rest_hessian.hpp"
#include "produce/sampling.hpp"

namespace yarnhom::yarn {

struct ProduceOptions {
  std::string preset = "quick";          // quick: 21 points per 1D term, 9 x 9 per 2D term;
                                         // paper: 101 and 31 x 31
  std::vector<Term> terms = all_terms();
  int threads = 1;                       // sectors solved in parallel
  // Run on the MPI ranks of an `mpirun` (core/cluster.hpp, produce_cluster.cpp): rank 0 hands
  // out the work, keeps the checkpoint and returns the dataset; every other rank solves what it
  // is sent and returns an empty dataset. The dataset is the same bits as one process's.
  bool ranks = false;
  int sectors = 8;                       // per 2D term (1D terms: 2, one per side)
  bool warm_start = true;                // false: every node from the rest state
  bool predictor = true;                 // warm starts add the first-order continuation step
  bool free_period = true;               // s = 0 is the stress-free tile (yarn/rve/rest.hpp); false:
                                         // the pattern's own period (pre-stressed)
  // The RVE: the pattern's relaxed tile repeated tiles_x x tiles_y times (docs/produce.md, "One
  // tile can be too small an RVE"). Psi is per reference area, so a patch samples the same
  // material; it lets neighbouring tiles buckle and slide differently, which one tile cannot.
  int tiles_x = 1, tiles_y = 1;
  Material material;
  std::map<int, Range> ranges;           // per strain index, overriding the pattern's defaults
  SolveOptions solve;
  // Wall-clock guard of the rest relaxation (s; 0: none). Node solves have none: a time limit
  // there would make the dataset depend on the machine's load.
  double rest_time_limit = 300;
  std::string checkpoint;                // sidecar file of finished samples and their states
                                         // (produce/produce_checkpoint.hpp; "" = none)
  // The branch pass (produce/branch_check.hpp): after every node is solved, each grid edge whose
  // energies and gradients disagree (trapezoid mismatch above branch_tolerance of the term's
  // typical edge change) has both its nodes solved again from the other's equilibrium; a node
  // moves to that branch when its energy there is lower, and its grid neighbours then try its
  // new branch in the next round. Repeated until nothing moves, at most branch_rounds times
  // (0: off; needs warm_start, which keeps the states).
  int branch_rounds = 12;
  double branch_tolerance = 0.05;
  // Called (from one thread at a time) after each finished node.
  std::function<void(int done, int total, int failed, double elapsed)> progress;
  // Called (from one thread at a time) after each node of a branch round.
  std::function<void(int round, int done, int total, int moved, double elapsed)> branch_progress;
};

int points_per_axis(const std::string& preset, int dim);  // throws for an unknown preset

// The sampling box of a strain component for a pattern: spec section 2, with the bending range
// of the paper's pattern of that name (stockinette 200/230, basket 170/170, honeycomb 120/120,
// cartridge belt rib 100/80 per m; 200/200 otherwise), then the overrides.
Range pattern_range(const std::string& pattern, int index, const std::map<int, Range>& overrides);

struct TermSummary {
  std::string name;
  int nodes = 0, failed = 0, resumed = 0;
  double mean_iterations = 0, seconds = 0, cpu_seconds = 0;  // solves' wall and CPU time
  // The branch pass: grid edges, those inconsistent as first solved and in the dataset, and the
  // nodes that moved to a lower-energy branch (this run and the resumed rounds together).
  int edges = 0, inconsistent_before = 0, inconsistent_after = 0, moved = 0;
  double worst_after = 0;          // largest relative mismatch left (branch_check.hpp)
};
struct Failure {
  std::string term;
  Strain s;
  std::string status;
};
// On MPI ranks: where one rank's time went (produce_cluster.cpp), for the summary.
struct RankLoad {
  double node_busy = 0;     // s solving the first pass's tasks
  double branch_busy = 0;   // s solving branch jobs' sources, those solved ahead included
  double ahead_lost = 0;    // of which jobs solved ahead that their round did not ask after all
  int tasks = 0, jobs = 0;  // first-pass tasks and branch solves (one source of a job) it ran
};
struct ProduceReport {
  RestReport rest;
  RestHessian rest_hessian;        // d2Psi/ds2 at s = 0, measured on the RVE (in the dataset when ok)
  std::vector<TermSummary> terms;
  std::vector<Failure> failures;   // nodes that did not converge warm, nor cold: not in the dataset
                                   // (status "topology_refused": converged, but along a path that
                                   // brought yarns within d_min; never stored)
  int refused = 0;                 // nodes whose every converged attempt was refused so
  // Smallest closest distance between yarn centrelines (m) over the whole certified paths of
  // the nodes solved in this run (rest state included); +inf if none.
  double min_separation = std::numeric_limits<double>::infinity();
  int resumed = 0;                 // samples read back from the checkpoint
  int branch_rounds = 0;           // branch rounds that ran (resumed ones included)
  std::uintmax_t checkpoint_dropped_bytes = 0;  // a record cut by the kill, removed (solved again)
  std::string checkpoint_error;    // why the checkpoint stopped being written ("" = it was not)
  double seconds = 0;              // wall time of this run
  double solve_seconds = 0;        // sum of the node solves' wall times
  double solve_cpu_seconds = 0;    // and CPU times (this run only; resumed samples excluded)
  // On MPI ranks: each rank's load (rank 0's solving thread included), the two passes' wall
  // times, the coordinator thread's CPU time, and the branch jobs solved ahead of their round
  // (docs/produce.md, "On a cluster").
  std::vector<RankLoad> rank_load;
  double node_pass_seconds = 0, branch_pass_seconds = 0, coordinator_cpu_seconds = 0;
  // The bounds that more ranks do not lower: the first pass's longest chain of warm starts (its
  // solves' seconds), and the sum over the branch rounds of each one's longest single solve.
  double node_critical_seconds = 0, branch_critical_seconds = 0;
  int ahead_solved = 0, ahead_used = 0;
};

Dataset produce(const Pattern& pattern, const ProduceOptions& opt, ProduceReport* report = nullptr);

}  // namespace yarnhom::yarn
