// The first pass of produce(): every node not resumed, sector by sector in the order of
// supplement Algorithm 1, each warm started from its parent's equilibrium (produce_pass.hpp).
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "produce/produce_pass.hpp"

namespace yarnhom::yarn {

namespace {

// Per strain axis: the normalization of term coordinates (the box's larger half-width) and
// the strain per unit normalized coordinate.
struct Axes {
  std::array<double, 6> scale;
  std::vector<Strain> direction = std::vector<Strain>(6, Strain::Zero());
};

Axes strain_axes(const ProduceRun& run) {
  Axes a;
  for (int i = 0; i < 6; ++i) {
    const Range r = pattern_range(run.pattern.name, i, run.opt.ranges);
    a.scale[i] = std::max(-r.lower, r.upper);
    a.direction[i][i] = a.scale[i];
  }
  return a;
}

std::vector<SectorTask> make_tasks(const ProduceRun& run, const Axes& axes) {
  const ProduceOptions& opt = run.opt;
  std::vector<SectorTask> tasks;
  for (size_t ti = 0; ti < opt.terms.size(); ++ti) {
    const Term& t = opt.terms[ti];
    const int K = t.dim() == 1 ? 2 : std::max(1, opt.sectors);
    std::vector<Strain> directions;
    for (int i : t.indices) directions.push_back(axes.direction[i]);
    std::vector<SectorTask> by_sector(K);
    for (int id : run.term_nodes_idx[ti]) {
      Eigen::VectorXd x = run.nodes[id].t;
      for (int d = 0; d < x.size(); ++d) x[d] /= axes.scale[t.indices[d]];
      const int k = sector_of(x, K);
      if (k < 0) continue;  // the origin
      by_sector[k].nodes.push_back(id);
      by_sector[k].x.push_back(x);
    }
    for (int k = 0; k < K; ++k) {
      if (by_sector[k].nodes.empty()) continue;
      by_sector[k].term = static_cast<int>(ti);
      by_sector[k].directions = directions;
      by_sector[k].plan = algorithm1(by_sector[k].x);
      tasks.push_back(std::move(by_sector[k]));
    }
  }
  return tasks;
}

// One task's nodes in plan order, with the solutions (and their sensitivities) that its
// children start from.
class TaskSolver {
 public:
  TaskSolver(ProduceRun& run, const SectorTask& task, const std::vector<Eigen::VectorXd>& rest_sensitivity, int& done,
             int& failed, int total)
      : run_(run), opt_(run.opt), rve_(run.rve()), task_(task), rest_sensitivity_(rest_sensitivity), done_(done),
        failed_(failed), total_(total) {
    solve_opt_ = opt_.solve;
    if (opt_.warm_start && opt_.predictor) solve_opt_.sensitivity_directions = task.directions;
  }

  void run() {
    for (int li : task_.plan.order) {
      ProduceNode& n = run_.nodes[task_.nodes[li]];
      const int parent = task_.plan.parent[li];
      if (n.done && n.state_needed) read_resumed(li, n);
      if (n.done) continue;
      solve(li, parent, n);
    }
  }

 private:
  // Resumed, with a child still to solve: that child starts from the very state this node
  // ended in, as it would have without the kill.
  void read_resumed(int li, ProduceNode& n) {
    if (run_.node_sink) {  // an MPI worker: the state came with the task
      CheckpointRecord& rec = run_.resumed_states.at(task_.nodes[li]);
      states_[li] = std::move(rec.state);
      if (!rec.sensitivity.empty()) sens_[li] = std::move(rec.sensitivity);
      return;
    }
    CheckpointRecord rec = run_.cc.records[n.record];
    try {
      read_checkpoint_state(opt_.checkpoint, run_.rest(), rec);
      states_[li] = std::move(rec.state);
      if (!rec.sensitivity.empty()) sens_[li] = std::move(rec.sensitivity);
    } catch (const std::exception& e) {
      // Solving it again from its parent's state gives the same bits (the solves are
      // deterministic); only time is lost.
      std::lock_guard<std::mutex> lock(run_.mu);
      if (run_.checkpoint_error.empty()) run_.checkpoint_error = e.what();
      n.done = n.resumed = false;
      --done_;
      --run_.rep.resumed;
    }
  }

  // The node's start: the rest state, or (warm start) the parent's solution as it is (Eq. 2-3,
  // see docs/produce.md); then, our addition, the first-order continuation predictor along the
  // step from the parent to this node, kept only if it lowers the energy at this node's strain.
  RveState start(int li, int parent, const ProduceNode& n) {
    RveState st = run_.rest();
    if (!(opt_.warm_start && (parent < 0 || states_.count(parent)))) return st;
    std::vector<const Eigen::VectorXd*> du;  // per term axis
    if (parent >= 0) {
      st = states_[parent];
      if (sens_.count(parent))
        for (const auto& v : sens_[parent]) du.push_back(&v);
    } else if (rest_sensitivity_.size() == 6) {
      for (int i : opt_.terms[task_.term].indices) du.push_back(&rest_sensitivity_[i]);
    }
    if (du.size() == task_.directions.size()) {
      const Eigen::VectorXd dx = parent >= 0 ? Eigen::VectorXd(task_.x[li] - task_.x[parent]) : task_.x[li];
      Eigen::VectorXd step = Eigen::VectorXd::Zero(rve_.num_dofs());
      for (size_t d = 0; d < du.size(); ++d) step += dx[d] * *du[d];
      RveState pred = st;
      rve_.apply_step(step, 1.0, pred);
      const double Ep = rve_.evaluate(n.s, pred), Em = rve_.evaluate(n.s, st);
      if (std::isfinite(Ep) && Ep < Em) st = std::move(pred);
    }
    return st;
  }

  // The attempts at one node, in order, until one converges with a valid topology certificate
  // (the path from the pattern through the rest state and every warm start to this node never
  // brought two yarn segments within d_min: docs/produce.md). A converged state without one is
  // refused, never stored.
  struct Attempts {
    DensityResult r;
    double secs = 0, cpu = 0;
    int iters = 0;
    bool refused = false;
  };
  bool attempt(Attempts& a, RveState& y, const Strain& target, const SolveOptions& so) {
    a.r = energy_density(rve_, target, y, so);
    a.secs += a.r.report.seconds;
    a.cpu += a.r.report.cpu_seconds;
    a.iters += a.r.report.iterations;
    return a.r.report.converged();
  }
  bool accept(Attempts& a, RveState& y, RveState& st) {
    if (!a.r.report.converged()) return false;
    if (y.certificate.valid) {
      st = std::move(y);
      return true;
    }
    a.refused = true;
    return false;
  }
  // Continuation from the equilibrium `from` (at its own strain) to the node in k equal strain
  // steps, each a solve.
  bool continuation(Attempts& a, const RveState& from, int k, const Strain& s, RveState& st) {
    RveState y = from;
    const Strain s0 = y.anchor.s;
    for (int j = 1; j <= k; ++j)
      if (!attempt(a, y, s0 + (s - s0) * (double(j) / k), j == k ? solve_opt_ : opt_.solve)) return false;
    return accept(a, y, st);
  }

  void solve(int li, int parent, ProduceNode& n) {
    RveState st = start(li, parent, n);
    Attempts a;
    const RveState* parent_state =
        opt_.warm_start && parent >= 0 && states_.count(parent) ? &states_[parent] : nullptr;
    RveState y = st;
    bool ok = attempt(a, y, n.s, solve_opt_) && accept(a, y, st);
    // Smaller continuation steps from the parent, then from the rest state (a cold start and
    // the ray from rest in 8 steps: the extreme corners of the boxes, large stretch with
    // large curvature, can defeat a single Newton solve from far away).
    if (!ok && parent_state) ok = continuation(a, *parent_state, 4, n.s, st);
    if (!ok && opt_.warm_start) ok = continuation(a, run_.rest(), 1, n.s, st);
    if (!ok) ok = continuation(a, run_.rest(), 8, n.s, st);
    n.psi = n.psi1 = a.r.psi;
    n.grad = n.grad1 = a.r.grad;
    n.status = ok ? "converged" : a.refused ? "topology_refused" : to_string(a.r.report.status);
    n.iterations = a.iters;
    n.seconds = a.secs;
    n.cpu_seconds = a.cpu;
    n.done = true;
    if (ok) {
      n.min_separation = st.certificate.min_distance;
      if (opt_.warm_start && opt_.branch_rounds > 0 && !run_.node_sink)
        run_.final_state[task_.nodes[li]] = std::make_shared<RveState>(st);
    }
    if (ok && opt_.warm_start) {
      states_[li] = std::move(st);
      if (!a.r.report.sensitivity.empty()) sens_[li] = std::move(a.r.report.sensitivity);
    }
    finished(li, n, ok, a.refused);
  }

  // Counts and checkpoints a finished node.
  void finished(int li, const ProduceNode& n, bool ok, bool refused) {
    std::lock_guard<std::mutex> lock(run_.mu);
    ++done_;
    if (!ok && refused) ++run_.rep.refused;
    if (!ok) ++failed_;
    if (run_.ck || run_.node_sink) {
      CheckpointRecord rec = record_of(n, n.status);
      // Copied into the record only while it is written (one at a time, under the lock).
      if (ok && opt_.warm_start) {
        rec.has_state = true;
        rec.state = states_[li];
        if (sens_.count(li)) rec.sensitivity = sens_[li];
      }
      if (run_.node_sink) {
        run_.node_sink(rec);
        return;
      }
      run_.append(rec);
    }
    if (opt_.progress) opt_.progress(done_, total_, failed_, run_.elapsed());
  }

  ProduceRun& run_;
  const ProduceOptions& opt_;
  const RveProblem& rve_;
  const SectorTask& task_;
  const std::vector<Eigen::VectorXd>& rest_sensitivity_;
  int &done_, &failed_;
  const int total_;
  SolveOptions solve_opt_;
  // Local index -> solution and its sensitivities, for the children's warm start.
  std::map<int, RveState> states_;
  std::map<int, std::vector<Eigen::VectorXd>> sens_;
};

}  // namespace

std::vector<SectorTask> sector_tasks(const ProduceRun& run) { return make_tasks(run, strain_axes(run)); }

std::vector<Eigen::VectorXd> rest_sensitivity(const ProduceRun& run) {
  // One factorization for all terms.
  if (!(run.opt.warm_start && run.opt.predictor)) return {};
  return equilibrium_sensitivity(run.rve(), Strain::Zero(), run.rest(), strain_axes(run).direction);
}

void mark_states_needed(ProduceRun& run, const std::vector<SectorTask>& tasks) {
  for (const SectorTask& task : tasks)
    for (size_t li = 0; li < task.nodes.size(); ++li) {
      const int parent = task.plan.parent[li];
      if (parent >= 0 && !run.nodes[task.nodes[li]].done) {
        ProduceNode& pn = run.nodes[task.nodes[parent]];
        pn.state_needed = pn.record >= 0 && run.cc.records[pn.record].has_state;
      }
    }
}

void solve_task(ProduceRun& run, const SectorTask& task, const std::vector<Eigen::VectorXd>& rest_sens, int& done,
                int& failed, int total) {
  TaskSolver(run, task, rest_sens, done, failed, total).run();
}

void first_pass(ProduceRun& run) {
  const std::vector<Eigen::VectorXd> rest_sens = rest_sensitivity(run);
  const std::vector<SectorTask> tasks = sector_tasks(run);
  // A resumed node's state is read back only if a child of it is still to be solved.
  mark_states_needed(run, tasks);
  int total = 0, done = 0, failed = 0;
  for (const auto& n : run.nodes) {
    ++total;
    if (n.done) ++done;
  }
  run.final_state.assign(run.nodes.size(), nullptr);

#pragma omp parallel for schedule(dynamic, 1) num_threads(run.threads)
  for (int ti = 0; ti < static_cast<int>(tasks.size()); ++ti) solve_task(run, tasks[ti], rest_sens, done, failed, total);
}

}  // namespace yarnhom::yarn
