#pragma once
// Internal to produce/: the state one produce() run (produce.cpp) shares among its steps, in
// their order: the rest tile and the rest Hessian (produce.cpp), the nodes and the checkpoint
// resumed from (produce_resume.cpp), the first pass of warm-started solves (first_pass.cpp),
// the branch pass (branch_pass.cpp), and the dataset written from the nodes
// (produce_dataset.cpp); on MPI ranks, the two passes' work spread by rank 0
// (produce_cluster.cpp).
#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "produce/branch_check.hpp"
#include "produce/produce.hpp"
#include "produce/produce_checkpoint.hpp"
#include "yarn/rve/energy_density.hpp"

namespace yarnhom::yarn {

// One node of a term's grid.
struct ProduceNode {
  int term = 0, index = 0;   // term position in opt.terms, node index in term_nodes order
  Eigen::VectorXd t;         // term coordinates
  Strain s;
  bool done = false, resumed = false;
  double psi = 0;
  Strain grad = Strain::Zero();
  std::string status;
  int iterations = 0;
  double seconds = 0, cpu_seconds = 0;
  double min_separation = std::numeric_limits<double>::infinity();  // certificate's closest distance (m)
  // Resumed: its record in the checkpoint (-1: none), whose state (converged nodes of warm
  // started runs) is read back when a child still to be solved starts from it.
  int record = -1;
  bool state_needed = false;
  // As first solved (before the branch pass), and whether the pass moved it.
  double psi1 = 0;
  Strain grad1 = Strain::Zero();
  bool moved = false;
  int branch_record = -1;  // resumed: its last branch record (-1: none)
};

// Checkpoint records of the branch pass: a node moved to a lower branch (its new state), and the
// end of a round (term -1, index = the round). A round is resumed only when its end is recorded.
inline constexpr char kLowerBranch[] = "lower-branch";
inline constexpr char kBranchRound[] = "branch-round";

// A branch-pass target's result in one round (branch_pass.cpp): whether a source's branch gave
// it a lower energy, and that equilibrium.
struct BranchMove {
  bool moved = false;
  double psi = 0, seconds = 0, cpu_seconds = 0;
  int iterations = 0;
  Strain grad = Strain::Zero();
  std::shared_ptr<const RveState> state;
};

// One target of a branch round: solved from each source's equilibrium (branch_solve), it moves
// when one gives an energy below best. These inputs decide its result, bit for bit.
struct BranchJob {
  int target = 0;
  double best = 0;
  std::vector<int> from;                                 // the sources' node ids, ascending
  std::vector<std::shared_ptr<const RveState>> states;   // their equilibria (null: none kept)
};
// A job of a later round (round), to be solved ahead of it.
struct AheadJob {
  int round = 0;
  BranchJob job;
};
// Given the moves of the round so far (known[k] null: job k not finished) and those of the jobs
// of later rounds already solved ahead (solved(round, job): the move if exactly that job was
// solved for that round, else null), the jobs of the following rounds that no unfinished job
// can change, as those rounds will ask them if none of the unfinished jobs moves (none for a
// round that may not follow). Whatever this says, each round is formed as in one process; a job
// solved ahead counts only if its round asks exactly it (same target, best and source states).
using BranchSolved = std::function<const BranchMove*(int round, const BranchJob& job)>;
using BranchPredict =
    std::function<std::vector<AheadJob>(const std::vector<const BranchMove*>& known, const BranchSolved& solved)>;

// A node's checkpoint record, without its state.
CheckpointRecord record_of(const ProduceNode& n, const std::string& status);

struct ProduceRun {
  ProduceRun(const Pattern& pattern, const ProduceOptions& opt, RestTile tile);
  const Pattern& pattern;
  const ProduceOptions& opt;
  const RestTile tile;  // the RVE and its rest state: the origin of every sector, and Psi0
  const RveProblem& rve() const { return tile.rve; }
  const RveState& rest() const { return tile.state; }
  DensityResult r0;     // Psi and dPsi/ds at rest
  int threads = 1;
  std::vector<ProduceNode> nodes;
  std::vector<std::vector<int>> term_nodes_idx;  // per term: its nodes' ids, in term_nodes order
  // The checkpoint: what was resumed from it, and the file appended to (null: none).
  CheckpointContents cc;
  std::FILE* ck = nullptr;
  std::string checkpoint_error;
  // Every converged node's state, for the branch pass (null: not kept, or resumed: read back
  // from the checkpoint when the pass needs it).
  std::vector<std::shared_ptr<const RveState>> final_state;
  ProduceReport rep;
  // On an MPI worker rank (produce_cluster.cpp): each finished node goes to node_sink (the
  // coordinator, rank 0) instead of the checkpoint and the progress line, and the states of
  // resumed nodes come from resumed_states (node id -> record, sent with the task) instead of
  // the checkpoint file, which only rank 0 reads and writes.
  std::function<void(const CheckpointRecord&)> node_sink;
  std::map<int, CheckpointRecord> resumed_states;
  // On rank 0 of an MPI run: a branch round's jobs solved on the ranks (null: on this process's
  // threads), one move per job. While the round runs, `next` tells which jobs of the next
  // rounds are already certain to be asked (produce_cluster.cpp solves them ahead).
  std::function<std::vector<BranchMove>(int round, const std::vector<BranchJob>& jobs, const BranchPredict& next)>
      branch_round;
  std::mutex mu;
  std::chrono::steady_clock::time_point t0;
  double elapsed() const;
  // Appends a record; a failure stops the checkpoint, not the work (the dataset is what
  // matters; only resuming is lost). Called from one thread at a time.
  void append(const CheckpointRecord& rec);
};

// Nodes of every term (the origin of each is the rest state, done).
void make_nodes(ProduceRun& run);
// Resume: samples finished by an earlier run of the same command, with the states they ended
// in (produce/produce_checkpoint.hpp), so that the run goes on exactly as if never stopped;
// then the checkpoint is opened for appending.
void resume_checkpoint(ProduceRun& run, const std::string& fingerprint);
// The first pass's unit of work (first_pass.cpp): one sector of one term, an Algorithm 1 plan
// over its nodes, each warm started from its parent's equilibrium. Tasks are independent (each
// starts from the rest state), so they may run in any order, on any thread or rank.
struct SectorTask {
  int term = 0;
  std::vector<int> nodes;            // global node ids
  std::vector<Eigen::VectorXd> x;    // their normalized coordinates
  std::vector<Strain> directions;    // strain per unit normalized coordinate, per term axis
  WarmStartPlan plan;
};
// Every rank builds the same list from the same nodes.
std::vector<SectorTask> sector_tasks(const ProduceRun& run);
// At rest, the equilibrium's sensitivity along each strain axis: the predictor of every
// sector's first node (empty without warm starts or the predictor).
std::vector<Eigen::VectorXd> rest_sensitivity(const ProduceRun& run);
// Marks the resumed nodes whose state a child still to be solved starts from.
void mark_states_needed(ProduceRun& run, const std::vector<SectorTask>& tasks);
// A task's nodes not yet done, in plan order; done and failed are counted under run.mu.
void solve_task(ProduceRun& run, const SectorTask& task, const std::vector<Eigen::VectorXd>& rest_sens, int& done,
                int& failed, int total);
// Every node not resumed, sector by sector with warm starts (supplement Algorithm 1), on this
// process's threads.
void first_pass(ProduceRun& run);
// The branch pass (ProduceOptions::branch_rounds, produce/branch_check.hpp).
void branch_pass(ProduceRun& run);
// While the first pass still runs on MPI ranks: the branch pass's first round's jobs of the terms
// whose nodes are all solved (complete, by term), which that round will ask exactly so (empty
// when the pass is off or resumed past its first round).
std::vector<BranchJob> first_round_ahead(ProduceRun& run, const std::vector<bool>& complete);
// One branch-pass target at strain s: a solve from each source's equilibrium straight to s; the
// lowest energy below `best` wins.
BranchMove branch_solve(const ProduceRun& run, const Strain& s, double best,
                        const std::vector<std::shared_ptr<const RveState>>& sources);
// On MPI ranks (produce_cluster.cpp, ProduceOptions::ranks): rank 0 runs both passes on the
// other ranks, which solve what they are sent until told to stop.
void cluster_coordinate(ProduceRun& run);
void cluster_work(ProduceRun& run);
// A term's grid edges and its typical edge changes, from the nodes as first solved or as now.
std::pair<std::vector<GridEdge>, std::vector<double>> term_edges(const ProduceRun& run, size_t ti, bool first);
// The dataset (spec section 3 targets) and the terms' summaries in run.rep.
Dataset assemble_dataset(ProduceRun& run);

}  // namespace yarnhom::yarn
