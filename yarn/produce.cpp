#include "yarn/produce.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"
#include "yarn/branch_check.hpp"
#include "yarn/energy_density.hpp"
#include "yarn/produce_checkpoint.hpp"

namespace yarnhom::yarn {

int points_per_axis(const std::string& preset, int dim) {
  if (preset == "quick") return dim == 1 ? 21 : 9;
  if (preset == "paper") return dim == 1 ? 101 : 31;
  if (preset == "tiny") return dim == 1 ? 5 : 3;  // for tests
  throw std::invalid_argument("unknown preset '" + preset + "' (known: quick, paper)");
}

Range pattern_range(const std::string& pattern, int index, const std::map<int, Range>& overrides) {
  auto it = overrides.find(index);
  if (it != overrides.end()) return it->second;
  double bx = 200, by = 200;
  if (pattern == "stockinette") bx = 200, by = 230;
  else if (pattern == "basket") bx = by = 170;
  else if (pattern == "slip_stitch_honeycomb") bx = by = 120;
  else if (pattern == "cartridge_belt_rib") bx = 100, by = 80;
  return default_range(index, bx, by);
}

namespace {

struct Node {
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
constexpr char kLowerBranch[] = "lower-branch";
constexpr char kBranchRound[] = "branch-round";

// A node's checkpoint record, without its state.
CheckpointRecord record_of(const Node& n, const std::string& status) {
  CheckpointRecord rec;
  rec.term = n.term;
  rec.index = n.index;
  rec.iterations = n.iterations;
  rec.seconds = n.seconds;
  rec.cpu_seconds = n.cpu_seconds;
  rec.status = status;
  rec.psi = n.psi;
  rec.grad = n.grad;
  rec.min_distance = n.min_separation;
  return rec;
}

std::string fingerprint(const Pattern& p, const ProduceOptions& opt) {
  std::ostringstream f;
  f.precision(17);
  // "contact=barrier-ccd": samples of runs before the collision filter and certificate are not
  // resumed (they may hold states with yarns passed through each other). The sectors and the
  // warm-start mode decide which state each node starts from: a resumed run must share them.
  f << p.name << " n=" << p.size() << " preset=" << opt.preset << " tol=" << opt.solve.tolerance
    << " rest=" << (opt.free_period ? "stress-free" : "pattern-period") << " contact=barrier-ccd height=mean"
    << " sectors=" << std::max(1, opt.sectors)
    << " start=" << (!opt.warm_start ? "cold" : opt.predictor ? "warm+predictor" : "warm")
    << " branch=" << (opt.warm_start ? opt.branch_rounds : 0) << "/" << opt.branch_tolerance << "/direct40";
  if (opt.tiles_x * opt.tiles_y > 1) f << " rve=" << opt.tiles_x << "x" << opt.tiles_y;
  for (const auto& t : opt.terms) f << " " << t.name;
  for (int i = 0; i < 6; ++i) {
    const Range r = pattern_range(p.name, i, opt.ranges);
    f << " [" << r.lower << "," << r.upper << "]";
  }
  std::string m = format_material(opt.material);
  for (char& c : m)
    if (c == '\n') c = ';';
  return f.str() + " " + m;
}

}  // namespace

Dataset produce(const Pattern& pattern, const ProduceOptions& opt, ProduceReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  ProduceReport rep;
  // The rest state: the origin of every sector, and Psi0. With free_period the tile's period
  // relaxes too and the RVE's reference is the relaxed tile (s = 0 stress free).
  RestOptions rest_opt;
  rest_opt.free_period = opt.free_period;
  rest_opt.solve = opt.solve;
  rest_opt.solve.sensitivity_directions.clear();
  rest_opt.max_seconds = opt.rest_time_limit;
  if (opt.tiles_x < 1 || opt.tiles_y < 1 || opt.tiles_x > 64 || opt.tiles_y > 64)
    throw std::invalid_argument("produce: the RVE's tiles must be 1..64 in each direction, got " +
                                std::to_string(opt.tiles_x) + " x " + std::to_string(opt.tiles_y));
  const int copies = opt.tiles_x * opt.tiles_y;
  RestTile tile = [&] {
    try {
      // A patch keeps one tile's rest: the same Psi0 and a stress-free s = 0.
      return repeat_rest(pattern, relax_tile(pattern, opt.material, rest_opt), opt.tiles_x, opt.tiles_y);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(std::string("produce: ") + e.what());
    }
  }();
  const RveProblem& rve = tile.rve;
  const RveState rest = tile.state;
  rep.rest = tile.report;
  if (!rest.certificate.valid)
    throw std::runtime_error("produce: pattern '" + pattern.name + "': " + summary(rest.certificate, 2 * pattern.radius));
  rep.min_separation = rest.certificate.min_distance;
  const DensityResult r0 = evaluate_density(rve, Strain::Zero(), rest);
  // The curvature of Psi at rest, which the grid does not resolve (yarn/rest_hessian.hpp): 12
  // small solves from the rest state, measured again on a resumed run (it is cheap and
  // deterministic).
  rep.rest_hessian = rest_hessian(rve, rest, opt.solve);

  // Nodes of every term.
  std::vector<Node> nodes;
  std::vector<std::vector<int>> term_nodes_idx(opt.terms.size());
  for (size_t ti = 0; ti < opt.terms.size(); ++ti) {
    const Term& t = opt.terms[ti];
    std::vector<Range> box;
    for (int i : t.indices) box.push_back(pattern_range(pattern.name, i, opt.ranges));
    const auto pts = term_nodes(t, box, points_per_axis(opt.preset, t.dim()));
    for (size_t k = 0; k < pts.size(); ++k) {
      Node n;
      n.term = static_cast<int>(ti);
      n.index = static_cast<int>(k);
      n.t = pts[k];
      n.s = Strain::Zero();
      for (int d = 0; d < t.dim(); ++d) n.s[t.indices[d]] = pts[k][d];
      if (n.t.norm() == 0) {  // the origin is the rest state
        n.done = true;
        n.psi = n.psi1 = r0.psi;
        n.grad = n.grad1 = r0.grad;
        n.status = "converged";
      }
      term_nodes_idx[ti].push_back(static_cast<int>(nodes.size()));
      nodes.push_back(std::move(n));
    }
  }

  // Resume: samples finished by an earlier run of the same command, with the states they ended
  // in (yarn/produce_checkpoint.hpp), so that the run goes on exactly as if never stopped.
  const std::string fp = fingerprint(pattern, opt);
  const std::string rest_sig = rest_signature(r0.psi, rest);
  std::FILE* ck = nullptr;
  CheckpointContents cc;
  if (!opt.checkpoint.empty()) {
    cc = read_checkpoint(opt.checkpoint, fp, rest_sig, rest);
    // Branch records after the last recorded round end belong to a round the kill cut short:
    // they are dropped (and cut from the file), and that round runs again from its start.
    {
      size_t keep = cc.records.size();
      for (size_t k = cc.records.size(); k-- > 0;) {
        if (cc.records[k].status == kBranchRound) break;
        if (cc.records[k].status == kLowerBranch) keep = k;
      }
      if (keep < cc.records.size()) {
        cc.dropped_bytes += cc.valid_bytes - cc.records[keep].offset;
        cc.valid_bytes = cc.records[keep].offset;
        cc.records.resize(keep);
      }
    }
    for (size_t k = 0; k < cc.records.size(); ++k) {
      const CheckpointRecord& rec = cc.records[k];
      if (rec.status == kBranchRound) {
        rep.branch_rounds = std::max(rep.branch_rounds, rec.index);
        continue;
      }
      if (rec.term < 0 || rec.term >= int(opt.terms.size()) || rec.index < 0 ||
          rec.index >= int(term_nodes_idx[rec.term].size()))
        throw FileError(opt.checkpoint, "", "a record of node " + std::to_string(rec.index) + " of term " +
                                                std::to_string(rec.term) + ", which this run does not have; remove it to start over");
      Node& n = nodes[term_nodes_idx[rec.term][rec.index]];
      if (rec.status == kLowerBranch) {
        if (!n.done || n.status != "converged" || !rec.has_state)
          throw FileError(opt.checkpoint, "", "a branch record of node " + std::to_string(rec.index) + " of term " +
                                                  std::to_string(rec.term) + " before its first solve; remove it to start over");
        n.psi = rec.psi;
        n.grad = rec.grad;
        n.iterations = rec.iterations;
        n.seconds = rec.seconds;
        n.cpu_seconds = rec.cpu_seconds;
        n.min_separation = rec.min_distance;
        n.branch_record = static_cast<int>(k);
        n.moved = true;
        continue;
      }
      if (n.done || rec.status != "converged") continue;  // failures are tried again
      if (opt.warm_start && !rec.has_state)
        throw FileError(opt.checkpoint, "", "a converged sample without its state in a warm-started run; remove it to start over");
      n.done = n.resumed = true;
      n.status = rec.status;
      n.iterations = rec.iterations;
      n.seconds = rec.seconds;
      n.cpu_seconds = rec.cpu_seconds;
      n.psi = n.psi1 = rec.psi;
      n.grad = n.grad1 = rec.grad;
      n.record = static_cast<int>(k);
      n.min_separation = rec.min_distance;
      ++rep.resumed;
    }
    rep.checkpoint_dropped_bytes = cc.dropped_bytes;
    ck = open_checkpoint(opt.checkpoint, fp, rest_sig, &cc);
  }
  std::string checkpoint_error;
  // Appends a record; a failure stops the checkpoint, not the work (the dataset is what
  // matters; only resuming is lost). Called from one thread at a time.
  auto append = [&](const CheckpointRecord& rec) {
    if (!ck) return;
    try {
      append_checkpoint(ck, opt.checkpoint, rec, rest);
    } catch (const std::exception& e) {
      checkpoint_error = e.what();
      std::fclose(ck);
      ck = nullptr;
    }
  };

  // Per strain axis: the normalization of term coordinates (the box's larger half-width) and
  // the strain per unit normalized coordinate; at rest, the equilibrium's sensitivity along
  // each (one factorization for all terms: the predictor of every sector's first node).
  std::array<double, 6> scale;
  std::vector<Strain> axis_direction(6, Strain::Zero());
  for (int i = 0; i < 6; ++i) {
    const Range r = pattern_range(pattern.name, i, opt.ranges);
    scale[i] = std::max(-r.lower, r.upper);
    axis_direction[i][i] = scale[i];
  }
  std::vector<Eigen::VectorXd> rest_sensitivity;
  if (opt.warm_start && opt.predictor) rest_sensitivity = equilibrium_sensitivity(rve, Strain::Zero(), rest, axis_direction);

  // Tasks: (term, sector), each an Algorithm 1 plan over its nodes.
  struct Task {
    int term = 0;
    std::vector<int> nodes;            // global node ids
    std::vector<Eigen::VectorXd> x;    // their normalized coordinates
    std::vector<Strain> directions;    // strain per unit normalized coordinate, per term axis
    WarmStartPlan plan;
  };
  std::vector<Task> tasks;
  for (size_t ti = 0; ti < opt.terms.size(); ++ti) {
    const Term& t = opt.terms[ti];
    const int K = t.dim() == 1 ? 2 : std::max(1, opt.sectors);
    std::vector<Strain> directions;
    for (int i : t.indices) directions.push_back(axis_direction[i]);
    std::vector<Task> by_sector(K);
    for (int id : term_nodes_idx[ti]) {
      Eigen::VectorXd x = nodes[id].t;
      for (int d = 0; d < x.size(); ++d) x[d] /= scale[t.indices[d]];
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
  // A resumed node's state is read back only if a child of it is still to be solved.
  for (const Task& task : tasks)
    for (size_t li = 0; li < task.nodes.size(); ++li) {
      const int parent = task.plan.parent[li];
      if (parent >= 0 && !nodes[task.nodes[li]].done) {
        Node& pn = nodes[task.nodes[parent]];
        pn.state_needed = pn.record >= 0 && cc.records[pn.record].has_state;
      }
    }
  int total = 0, done = 0, failed = 0;
  for (const auto& n : nodes) {
    ++total;
    if (n.done) ++done;
  }
  std::mutex mu;
  const int threads = std::max(1, opt.threads);
  // Every converged node's state, for the branch pass (null: not kept, or resumed: read back
  // from the checkpoint when the pass needs it).
  std::vector<std::shared_ptr<const RveState>> final_state(nodes.size());

#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int ti = 0; ti < static_cast<int>(tasks.size()); ++ti) {
    const Task& task = tasks[ti];
    // Local index -> solution and its sensitivities, for the children's warm start.
    std::map<int, RveState> states;
    std::map<int, std::vector<Eigen::VectorXd>> sens;
    SolveOptions solve_opt = opt.solve;
    if (opt.warm_start && opt.predictor) solve_opt.sensitivity_directions = task.directions;
    for (int li : task.plan.order) {
      Node& n = nodes[task.nodes[li]];
      const int parent = task.plan.parent[li];
      if (n.done && n.state_needed) {
        // Resumed, with a child still to solve: that child starts from the very state this
        // node ended in, as it would have without the kill.
        CheckpointRecord rec = cc.records[n.record];
        try {
          read_checkpoint_state(opt.checkpoint, rest, rec);
          states[li] = std::move(rec.state);
          if (!rec.sensitivity.empty()) sens[li] = std::move(rec.sensitivity);
        } catch (const std::exception& e) {
          // Solving it again from its parent's state gives the same bits (the solves are
          // deterministic); only time is lost.
          std::lock_guard<std::mutex> lock(mu);
          if (checkpoint_error.empty()) checkpoint_error = e.what();
          n.done = n.resumed = false;
          --done;
          --rep.resumed;
        }
      }
      if (n.done) continue;
      RveState st = rest;
      if (opt.warm_start && (parent < 0 || states.count(parent))) {
        // Eq. 2-3: the parent's solution as it is (see docs/produce.md); then, our addition,
        // the first-order continuation predictor along the step from the parent to this node,
        // kept only if it lowers the energy at this node's strain.
        std::vector<const Eigen::VectorXd*> du;  // per term axis
        if (parent >= 0) {
          st = states[parent];
          if (sens.count(parent))
            for (const auto& v : sens[parent]) du.push_back(&v);
        } else if (rest_sensitivity.size() == 6) {
          for (int i : opt.terms[task.term].indices) du.push_back(&rest_sensitivity[i]);
        }
        if (du.size() == task.directions.size()) {
          const Eigen::VectorXd dx = parent >= 0 ? Eigen::VectorXd(task.x[li] - task.x[parent]) : task.x[li];
          Eigen::VectorXd step = Eigen::VectorXd::Zero(rve.num_dofs());
          for (size_t d = 0; d < du.size(); ++d) step += dx[d] * *du[d];
          RveState pred = st;
          rve.apply_step(step, 1.0, pred);
          const double Ep = rve.evaluate(n.s, pred), Em = rve.evaluate(n.s, st);
          if (std::isfinite(Ep) && Ep < Em) st = std::move(pred);
        }
      }
      // Attempts, in order, until one converges with a valid topology certificate (the path
      // from the pattern through the rest state and every warm start to this node never
      // brought two yarn segments within d_min: docs/produce.md). A converged state without
      // one is refused, never stored.
      DensityResult r;
      double secs = 0, cpu = 0;
      int iters = 0;
      bool refused = false;
      auto run = [&](RveState& y, const Strain& target, const SolveOptions& so) {
        r = energy_density(rve, target, y, so);
        secs += r.report.seconds;
        cpu += r.report.cpu_seconds;
        iters += r.report.iterations;
        return r.report.converged();
      };
      auto accept = [&](RveState& y) {
        if (!r.report.converged()) return false;
        if (y.certificate.valid) {
          st = std::move(y);
          return true;
        }
        refused = true;
        return false;
      };
      // Continuation from the equilibrium `from` (at its own strain) to the node in k equal
      // strain steps, each a solve.
      auto continuation = [&](const RveState& from, int k) {
        RveState y = from;
        const Strain s0 = y.anchor.s;
        for (int j = 1; j <= k; ++j)
          if (!run(y, s0 + (n.s - s0) * (double(j) / k), j == k ? solve_opt : opt.solve)) return false;
        return accept(y);
      };
      const RveState* parent_state = opt.warm_start && parent >= 0 && states.count(parent) ? &states[parent] : nullptr;
      RveState y = st;
      bool ok = run(y, n.s, solve_opt) && accept(y);
      // Smaller continuation steps from the parent, then from the rest state (a cold start and
      // the ray from rest in 8 steps: the extreme corners of the boxes, large stretch with
      // large curvature, can defeat a single Newton solve from far away).
      if (!ok && parent_state) ok = continuation(*parent_state, 4);
      if (!ok && opt.warm_start) ok = continuation(rest, 1);
      if (!ok) ok = continuation(rest, 8);
      n.psi = n.psi1 = r.psi;
      n.grad = n.grad1 = r.grad;
      n.status = ok ? "converged" : refused ? "topology_refused" : to_string(r.report.status);
      n.iterations = iters;
      n.seconds = secs;
      n.cpu_seconds = cpu;
      n.done = true;
      if (ok) {
        n.min_separation = st.certificate.min_distance;
        if (opt.warm_start && opt.branch_rounds > 0) final_state[task.nodes[li]] = std::make_shared<RveState>(st);
      }
      if (ok && opt.warm_start) {
        states[li] = std::move(st);
        if (!r.report.sensitivity.empty()) sens[li] = std::move(r.report.sensitivity);
      }
      std::lock_guard<std::mutex> lock(mu);
      ++done;
      if (!ok && refused) ++rep.refused;
      if (!ok) ++failed;
      if (ck) {
        CheckpointRecord rec = record_of(n, n.status);
        // Copied into the record only while it is written (one at a time, under the lock).
        if (ok && opt.warm_start) {
          rec.has_state = true;
          rec.state = states[li];
          if (sens.count(li)) rec.sensitivity = sens[li];
        }
        append(rec);
      }
      if (opt.progress) opt.progress(done, total, failed, elapsed());
    }
  }
  // The branch pass (ProduceOptions::branch_rounds, yarn/branch_check.hpp).
  auto term_edges = [&](size_t ti, bool first) {
    const Term& t = opt.terms[ti];
    std::vector<Eigen::VectorXd> x, g;
    std::vector<double> psi;
    std::vector<bool> ok;
    for (int id : term_nodes_idx[ti]) {
      const Node& n = nodes[id];
      x.push_back(n.t);
      psi.push_back(first ? n.psi1 : n.psi);
      Eigen::VectorXd gi(t.dim());
      for (int d = 0; d < t.dim(); ++d) gi[d] = (first ? n.grad1 : n.grad)[t.indices[d]];
      g.push_back(gi);
      ok.push_back(n.status == "converged");
    }
    const int m = points_per_axis(opt.preset, t.dim());
    return std::make_pair(grid_edges(t.dim(), m, x, psi, g, ok), edge_scales(t.dim(), m, x, g, ok));
  };
  if (opt.warm_start && opt.branch_rounds > 0) {
    // Grid neighbours of every node, and each term's smallest meaningful energy gain.
    std::vector<std::vector<int>> neighbours(nodes.size());
    std::vector<double> term_gain(opt.terms.size());
    for (size_t ti = 0; ti < opt.terms.size(); ++ti) {
      const auto [edges, scale] = term_edges(ti, false);
      term_gain[ti] = 1e-2 * opt.branch_tolerance * *std::min_element(scale.begin(), scale.end());
      for (const GridEdge& e : edges) {
        neighbours[term_nodes_idx[ti][e.a]].push_back(term_nodes_idx[ti][e.b]);
        neighbours[term_nodes_idx[ti][e.b]].push_back(term_nodes_idx[ti][e.a]);
      }
    }
    // The nodes that moved in the previous round: their neighbours try the new branch too (a
    // lower branch spreads along the grid one node per round). A resumed run recomputes them
    // from the records of the last round it finished.
    std::vector<int> moved_last;
    if (rep.branch_rounds > 0)
      for (size_t k = 0, round = 0; k < cc.records.size(); ++k) {
        if (cc.records[k].status == kBranchRound) {
          round = cc.records[k].index;
          continue;
        }
        if (cc.records[k].status == kLowerBranch && int(round) == rep.branch_rounds - 1)
          moved_last.push_back(term_nodes_idx[cc.records[k].term][cc.records[k].index]);
      }
    // A finished round that moved nothing ended the pass (a resumed run must not run another).
    const bool finished = rep.branch_rounds > 0 && moved_last.empty();
    // (target, source) pairs already tried that did not move the target: the same two states
    // give the same solve, so they are tried again only after one of the two has moved. (Not
    // checkpointed: a resumed run tries them once more, finds the same, and ends the same.)
    std::set<std::pair<int, int>> tried;
    for (int round = rep.branch_rounds + 1; !finished && round <= opt.branch_rounds; ++round) {
      // Each inconsistent edge: both its nodes try the other's branch. Every node's energy may
      // only go down, by more than a small part of the flagging threshold, so no node ever
      // returns to a branch it left and the rounds end.
      std::map<int, std::vector<int>> sources;
      std::map<int, double> min_gain;
      for (int id : moved_last)
        for (int nb : neighbours[id])
          if (nodes[nb].t.norm() > 0 && nodes[nb].status == "converged")
            sources[nb].push_back(id), min_gain[nb] = term_gain[nodes[nb].term];
      for (size_t ti = 0; ti < opt.terms.size(); ++ti) {
        const auto [edges, scale] = term_edges(ti, false);
        const double gain = term_gain[ti];
        for (const GridEdge& e : inconsistent_edges(edges, opt.branch_tolerance)) {
          // The origin is the rest state by definition (s = 0 is the relaxed tile): never a target.
          const int a = term_nodes_idx[ti][e.a], b = term_nodes_idx[ti][e.b];
          if (nodes[a].t.norm() > 0) sources[a].push_back(b), min_gain[a] = gain;
          if (nodes[b].t.norm() > 0) sources[b].push_back(a), min_gain[b] = gain;
        }
      }
      for (auto it = sources.begin(); it != sources.end();) {
        auto& from = it->second;
        from.erase(std::remove_if(from.begin(), from.end(), [&](int src) { return tried.count({it->first, src}) > 0; }),
                   from.end());
        it = from.empty() ? sources.erase(it) : std::next(it);
      }
      if (sources.empty()) break;
      // The sources' states, read back serially (the checkpoint file is one stream).
      for (auto& [target, from] : sources) {
        std::sort(from.begin(), from.end());
        from.erase(std::unique(from.begin(), from.end()), from.end());
        for (int id : from) {
          if (final_state[id]) continue;
          const Node& n = nodes[id];
          const int record = n.branch_record >= 0 ? n.branch_record : n.record;
          if (n.t.norm() == 0) {
            final_state[id] = std::make_shared<RveState>(rest);
          } else if (record >= 0 && cc.records[record].has_state) {
            CheckpointRecord rec = cc.records[record];
            read_checkpoint_state(opt.checkpoint, rest, rec);
            final_state[id] = std::make_shared<RveState>(std::move(rec.state));
          }
        }
      }
      struct Move {
        bool moved = false;
        double psi = 0, seconds = 0, cpu_seconds = 0;
        int iterations = 0;
        Strain grad = Strain::Zero();
        std::shared_ptr<const RveState> state;
      };
      std::vector<int> targets;
      for (const auto& [target, from] : sources) targets.push_back(target);
      std::vector<Move> moves(targets.size());
      int round_done = 0, round_moved = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
      for (int k = 0; k < static_cast<int>(targets.size()); ++k) {
        const Node& n = nodes[targets[k]];
        Move& mv = moves[k];
        double best = n.psi - min_gain[targets[k]];
        // A neighbour's branch is one grid step away: a solve that needs more than a few dozen
        // Newton iterations from there (the basket's hard corners crawl for hundreds) is not
        // continuing that branch, and is given up (measured on the basket, quick preset: the
        // late rounds' few nodes took 10 s each with the full budget and a 4-step retry).
        SolveOptions pass_solve = opt.solve;
        pass_solve.max_iterations = std::min(pass_solve.max_iterations, 40);
        for (int src : sources[targets[k]]) {
          if (!final_state[src]) continue;
          // From the neighbour's equilibrium straight to this node's strain.
          RveState y = *final_state[src];
          const DensityResult r = energy_density(rve, n.s, y, pass_solve);
          mv.seconds += r.report.seconds;
          mv.cpu_seconds += r.report.cpu_seconds;
          mv.iterations += r.report.iterations;
          if (r.report.converged() && y.certificate.valid && r.psi < best) {
            best = r.psi;
            mv.moved = true;
            mv.psi = r.psi;
            mv.grad = r.grad;
            mv.state = std::make_shared<RveState>(std::move(y));
          }
        }
        std::lock_guard<std::mutex> lock(mu);
        ++round_done;
        if (mv.moved) ++round_moved;
        if (opt.branch_progress) opt.branch_progress(round, round_done, int(targets.size()), round_moved, elapsed());
      }
      // Applied together, in node order: the round's result does not depend on the threads.
      for (const auto& [target, from] : sources)
        for (int src : from) tried.insert({target, src});
      moved_last.clear();
      for (size_t k = 0; k < targets.size(); ++k) {
        Node& n = nodes[targets[k]];
        const Move& mv = moves[k];
        n.iterations += mv.iterations;
        n.seconds += mv.seconds;
        n.cpu_seconds += mv.cpu_seconds;
        if (!mv.moved) continue;
        n.psi = mv.psi;
        n.grad = mv.grad;
        n.moved = true;
        moved_last.push_back(targets[k]);
        for (auto it = tried.begin(); it != tried.end();)
          it = it->first == targets[k] || it->second == targets[k] ? tried.erase(it) : std::next(it);
        n.min_separation = mv.state->certificate.min_distance;
        final_state[targets[k]] = mv.state;
        if (ck) {
          CheckpointRecord rec = record_of(n, kLowerBranch);
          rec.has_state = true;
          rec.state = *mv.state;
          append(rec);
        }
      }
      CheckpointRecord end;
      end.term = -1;
      end.index = round;
      end.status = kBranchRound;
      append(end);
      rep.branch_rounds = round;
      if (round_moved == 0) break;
    }
  }
  if (ck) std::fclose(ck);
  rep.checkpoint_error = checkpoint_error;

  // Assemble the dataset (spec section 3 targets).
  Dataset ds;
  ds.pattern = pattern.name;
  ds.source = "yarn-rve";
  ds.psi0 = r0.psi;
  ds.rest_q.resize(rest.packed().size());
  Eigen::VectorXd::Map(ds.rest_q.data(), ds.rest_q.size()) = rest.packed();
  const Eigen::Matrix2d L = rve.lattice();
  ds.lattice_original = {pattern.px * opt.tiles_x, 0.0, 0.0, pattern.py * opt.tiles_y};
  if (copies > 1) ds.rve_tiles = {double(opt.tiles_x), double(opt.tiles_y)};
  ds.lattice_relaxed = {L(0, 0), L(1, 0), L(0, 1), L(1, 1)};
  ds.grad0.assign(r0.grad.data(), r0.grad.data() + 6);
  if (rep.rest_hessian.ok)  // symmetric: its storage order is row-major as well
    ds.rest_hessian.assign(rep.rest_hessian.H.data(), rep.rest_hessian.H.data() + 36);
  ds.areal_density = areal_density(rve);
  {
    std::ostringstream note;
    note.precision(9);
    note << "yarnhom produce, preset " << opt.preset << ", " << (opt.warm_start ? "warm start" : "cold start")
         << (copies > 1 ? "; RVE: " + std::to_string(opt.tiles_x) + " x " + std::to_string(opt.tiles_y) + " tiles" : "")
         << "; rest: " << (opt.free_period ? "stress-free tile, relaxed from the pattern's period by (s_x, s_a, s_y) = ("
                                           : "the pattern's period, pre-stressed (")
         << tile.report.strain[0] << ", " << tile.report.strain[1] << ", " << tile.report.strain[2]
         << "); material: " << format_material(opt.material);
    ds.note = note.str();
  }
  for (size_t ti = 0; ti < opt.terms.size(); ++ti) {
    const Term& t = opt.terms[ti];
    TermSummary sum;
    sum.name = t.name;
    TermData td;
    td.term = t;
    for (int i : t.indices) {
      const Range r = pattern_range(pattern.name, i, opt.ranges);
      td.lower.push_back(r.lower);
      td.upper.push_back(r.upper);
    }
    const auto& ids = term_nodes_idx[ti];
    auto ok = [&](const Node& n) { return n.status == "converged"; };
    int iters = 0;
    for (int id : ids) {
      const Node& n = nodes[id];
      ++sum.nodes;
      if (n.resumed) ++sum.resumed;
      sum.seconds += n.seconds;
      sum.cpu_seconds += n.cpu_seconds;
      iters += n.iterations;
      if (!ok(n)) {
        ++sum.failed;
        rep.failures.push_back({t.name, n.s, n.status});
      }
    }
    sum.mean_iterations = sum.nodes ? double(iters) / sum.nodes : 0;
    {
      const auto before = term_edges(ti, true).first, after = term_edges(ti, false).first;
      sum.edges = static_cast<int>(after.size());
      sum.inconsistent_before = static_cast<int>(inconsistent_edges(before, opt.branch_tolerance).size());
      sum.inconsistent_after = static_cast<int>(inconsistent_edges(after, opt.branch_tolerance).size());
      for (const GridEdge& e : after) sum.worst_after = std::max(sum.worst_after, e.relative);
      for (int id : ids) sum.moved += nodes[id].moved;
    }
    for (int id : ids)
      if (ok(nodes[id])) rep.min_separation = std::min(rep.min_separation, nodes[id].min_separation);
    rep.solve_seconds += sum.seconds;
    rep.solve_cpu_seconds += sum.cpu_seconds;
    if (t.dim() == 1) {
      const int I = t.indices[0];
      for (int id : ids) {
        const Node& n = nodes[id];
        if (!ok(n)) continue;
        td.strain.push_back(n.t[0]);
        td.raw.push_back(n.psi - r0.psi);
        td.energy.push_back(n.psi - r0.psi);
        td.gradient.push_back(n.grad[I]);
      }
    } else {
      const int I = t.indices[0], J = t.indices[1];
      const int m = points_per_axis(opt.preset, 2);
      // The grid is row-major: node (i, j) has a = axis_a[i], b = axis_b[j]; its axis nodes
      // are (i, j0) and (i0, j) with j0, i0 the positions of 0.
      int i0 = -1, j0 = -1;
      for (int k = 0; k < m; ++k) {
        if (nodes[ids[k * m]].t[0] == 0) i0 = k;
        if (nodes[ids[k]].t[1] == 0) j0 = k;
      }
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
          const Node& n = nodes[ids[i * m + j]];
          const Node& na = nodes[ids[i * m + j0]];  // (a, 0)
          const Node& nb = nodes[ids[i0 * m + j]];  // (0, b)
          if (!ok(n) || !ok(na) || !ok(nb)) continue;
          const double psi_a = na.psi - r0.psi, psi_b = nb.psi - r0.psi;
          td.strain.insert(td.strain.end(), {n.t[0], n.t[1]});
          td.raw.push_back(n.psi - r0.psi);
          td.energy.push_back(n.psi - r0.psi - psi_a - psi_b);
          td.gradient.insert(td.gradient.end(), {n.grad[I] - na.grad[I], n.grad[J] - nb.grad[J]});
        }
    }
    td.n = static_cast<int>(td.energy.size());
    ds.terms.push_back(std::move(td));
    rep.terms.push_back(sum);
  }
  rep.seconds = elapsed();
  if (report) *report = rep;
  return ds;
}

}  // namespace yarnhom::yarn
