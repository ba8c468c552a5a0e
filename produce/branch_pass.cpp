// The branch pass of produce() (ProduceOptions::branch_rounds, produce/branch_check.hpp): each
// grid edge whose energies and gradients disagree has both its nodes solved again from the
// other's equilibrium; a node moves to that branch when its energy there is lower, and its grid
// neighbours try its new branch in the next round (produce_pass.hpp).
#include <omp.h>

#include <algorithm>
#include <map>
#include <set>
#include <vector>

#include "produce/produce_pass.hpp"

namespace yarnhom::yarn {

std::pair<std::vector<GridEdge>, std::vector<double>> term_edges(const ProduceRun& run, size_t ti, bool first) {
  const Term& t = run.opt.terms[ti];
  std::vector<Eigen::VectorXd> x, g;
  std::vector<double> psi;
  std::vector<bool> ok;
  for (int id : run.term_nodes_idx[ti]) {
    const ProduceNode& n = run.nodes[id];
    x.push_back(n.t);
    psi.push_back(first ? n.psi1 : n.psi);
    Eigen::VectorXd gi(t.dim());
    for (int d = 0; d < t.dim(); ++d) gi[d] = (first ? n.grad1 : n.grad)[t.indices[d]];
    g.push_back(gi);
    ok.push_back(n.status == "converged");
  }
  const int m = points_per_axis(run.opt.preset, t.dim());
  return std::make_pair(grid_edges(t.dim(), m, x, psi, g, ok), edge_scales(t.dim(), m, x, g, ok));
}

namespace {

class BranchPass {
 public:
  explicit BranchPass(ProduceRun& run) : run_(run), opt_(run.opt), nodes_(run.nodes) {}

  // The first round's jobs of the terms whose nodes are all solved (complete[term]): a term's
  // first round depends on its own nodes only (its edges, its typical edge change, no pairs
  // tried yet), so these are the very jobs the round will ask.
  std::vector<BranchJob> first_round(const std::vector<bool>& complete) {
    grid_neighbours();
    std::map<int, std::vector<int>> sources = round_sources();
    for (auto it = sources.begin(); it != sources.end();)
      it = complete[nodes_[it->first].term] ? std::next(it) : sources.erase(it);
    load_source_states(sources);
    std::vector<BranchJob> jobs;
    for (const auto& [target, from] : sources) jobs.push_back(job(target, from, nodes_[target].psi - min_gain_.at(target)));
    return jobs;
  }

  void run() {
    grid_neighbours();
    moved_in_resumed_round();
    // A finished round that moved nothing ended the pass (a resumed run must not run another).
    const bool finished = run_.rep.branch_rounds > 0 && moved_last_.empty();
    for (int round = run_.rep.branch_rounds + 1; !finished && round <= opt_.branch_rounds; ++round) {
      std::map<int, std::vector<int>> sources = round_sources();
      if (sources.empty()) break;
      load_source_states(sources);
      std::vector<int> targets;
      for (const auto& [target, from] : sources) targets.push_back(target);
      const std::vector<BranchMove> moves = solve_round(round, sources, targets);
      apply_round(sources, targets, moves);
      CheckpointRecord end;
      end.term = -1;
      end.index = round;
      end.status = kBranchRound;
      run_.append(end);
      run_.rep.branch_rounds = round;
      if (round_moved_ == 0) break;
    }
  }

 private:
  // Grid neighbours of every node, and each term's smallest meaningful energy gain.
  void grid_neighbours() {
    neighbours_.assign(nodes_.size(), {});
    term_gain_.assign(opt_.terms.size(), 0.0);
    for (size_t ti = 0; ti < opt_.terms.size(); ++ti) {
      const auto [edges, scale] = term_edges(run_, ti, false);
      term_gain_[ti] = 1e-2 * opt_.branch_tolerance * *std::min_element(scale.begin(), scale.end());
      for (const GridEdge& e : edges) {
        neighbours_[run_.term_nodes_idx[ti][e.a]].push_back(run_.term_nodes_idx[ti][e.b]);
        neighbours_[run_.term_nodes_idx[ti][e.b]].push_back(run_.term_nodes_idx[ti][e.a]);
      }
    }
  }

  // The nodes that moved in the previous round: their neighbours try the new branch too (a
  // lower branch spreads along the grid one node per round). A resumed run recomputes them
  // from the records of the last round it finished.
  void moved_in_resumed_round() {
    const CheckpointContents& cc = run_.cc;
    if (run_.rep.branch_rounds > 0)
      for (size_t k = 0, round = 0; k < cc.records.size(); ++k) {
        if (cc.records[k].status == kBranchRound) {
          round = cc.records[k].index;
          continue;
        }
        if (cc.records[k].status == kLowerBranch && int(round) == run_.rep.branch_rounds - 1)
          moved_last_.push_back(run_.term_nodes_idx[cc.records[k].term][cc.records[k].index]);
      }
  }

  // Each inconsistent edge: both its nodes try the other's branch. Every node's energy may
  // only go down, by more than a small part of the flagging threshold, so no node ever returns
  // to a branch it left and the rounds end. Pairs already tried are left out.
  std::map<int, std::vector<int>> round_sources() {
    std::map<int, std::vector<int>> sources;
    min_gain_.clear();
    for (int id : moved_last_)
      for (int nb : neighbours_[id])
        if (nodes_[nb].t.norm() > 0 && nodes_[nb].status == "converged")
          sources[nb].push_back(id), min_gain_[nb] = term_gain_[nodes_[nb].term];
    for (size_t ti = 0; ti < opt_.terms.size(); ++ti) {
      const auto [edges, scale] = term_edges(run_, ti, false);
      const double gain = term_gain_[ti];
      for (const GridEdge& e : inconsistent_edges(edges, opt_.branch_tolerance)) {
        // The origin is the rest state by definition (s = 0 is the relaxed tile): never a target.
        const int a = run_.term_nodes_idx[ti][e.a], b = run_.term_nodes_idx[ti][e.b];
        if (nodes_[a].t.norm() > 0) sources[a].push_back(b), min_gain_[a] = gain;
        if (nodes_[b].t.norm() > 0) sources[b].push_back(a), min_gain_[b] = gain;
      }
    }
    for (auto it = sources.begin(); it != sources.end();) {
      auto& from = it->second;
      from.erase(std::remove_if(from.begin(), from.end(), [&](int src) { return tried_.count({it->first, src}) > 0; }),
                 from.end());
      it = from.empty() ? sources.erase(it) : std::next(it);
    }
    return sources;
  }

  // The sources' states, read back serially (the checkpoint file is one stream).
  void load_source_states(std::map<int, std::vector<int>>& sources) {
    for (auto& [target, from] : sources) {
      std::sort(from.begin(), from.end());
      from.erase(std::unique(from.begin(), from.end()), from.end());
      for (int id : from) {
        if (run_.final_state[id]) continue;
        const ProduceNode& n = nodes_[id];
        const int record = n.branch_record >= 0 ? n.branch_record : n.record;
        if (n.t.norm() == 0) {
          run_.final_state[id] = std::make_shared<RveState>(run_.rest());
        } else if (record >= 0 && run_.cc.records[record].has_state) {
          CheckpointRecord rec = run_.cc.records[record];
          read_checkpoint_state(opt_.checkpoint, run_.rest(), rec);
          run_.final_state[id] = std::make_shared<RveState>(std::move(rec.state));
        }
      }
    }
  }

  // Each target's threshold: its energy less the term's gain.
  std::vector<BranchMove> solve_round(int round, const std::map<int, std::vector<int>>& sources,
                                      const std::vector<int>& targets) {
    std::vector<double> best(targets.size());
    for (size_t k = 0; k < targets.size(); ++k) best[k] = nodes_[targets[k]].psi - min_gain_.at(targets[k]);
    if (run_.branch_round) {  // on the MPI ranks (produce_cluster.cpp)
      std::vector<BranchJob> jobs;
      for (size_t k = 0; k < targets.size(); ++k) jobs.push_back(job(targets[k], sources.at(targets[k]), best[k]));
      std::vector<BranchMove> moves = run_.branch_round(
          round, jobs, [&](const std::vector<const BranchMove*>& known, const BranchSolved& solved) {
            return ahead(round, sources, targets, known, solved);
          });
      round_moved_ = int(std::count_if(moves.begin(), moves.end(), [](const BranchMove& m) { return m.moved; }));
      return moves;
    }
    std::vector<BranchMove> moves(targets.size());
    int round_done = 0;
    round_moved_ = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(run_.threads)
    for (int k = 0; k < static_cast<int>(targets.size()); ++k) {
      std::vector<std::shared_ptr<const RveState>> from;
      for (int src : sources.at(targets[k])) from.push_back(run_.final_state[src]);
      moves[k] = branch_solve(run_, nodes_[targets[k]].s, best[k], from);
      std::lock_guard<std::mutex> lock(run_.mu);
      ++round_done;
      if (moves[k].moved) ++round_moved_;
      if (opt_.branch_progress)
        opt_.branch_progress(round, round_done, int(targets.size()), round_moved_, run_.elapsed());
    }
    return moves;
  }

  BranchJob job(int target, const std::vector<int>& from, double best) const {
    BranchJob j;
    j.target = target;
    j.best = best;
    j.from = from;
    for (int src : from) j.states.push_back(run_.final_state[src]);
    return j;
  }

  // While a round runs on the ranks (BranchPredict, produce_pass.hpp): the jobs of the next
  // rounds as they would be formed if none of the unfinished jobs moves, kept only where nothing
  // unfinished can change them. A node whose state after a round is not known: a target of that
  // round not finished (or not solved ahead), and any node whose own status in that round was
  // not certain. A job of the next round is certain when neither its target nor a grid
  // neighbour is such a node (they decide its sources, its energy and the pairs tried). Each
  // round is applied to the nodes as far as it is known, the next one's sources taken, and so on
  // while a known job moved (else the pass may end there); then everything is put back as it
  // was. (The edges' typical change is a mean over the term, so an unfinished move can still
  // change an edge far away: rank 0 uses a job solved ahead only if its round asks exactly it.)
  std::vector<AheadJob> ahead(int round, const std::map<int, std::vector<int>>& sources, const std::vector<int>& targets,
                              const std::vector<const BranchMove*>& known, const BranchSolved& solved) {
    std::set<int> unknown;
    bool any_moved = false;
    std::vector<BranchMove> moves(targets.size());
    for (size_t k = 0; k < targets.size(); ++k) {
      if (!known[k]) unknown.insert(targets[k]);
      else moves[k] = *known[k], any_moved |= known[k]->moved;
    }
    struct Saved {
      int node;
      double psi, seconds, cpu_seconds, min_separation;
      Strain grad;
      int iterations;
      bool moved, state_changed;
      std::shared_ptr<const RveState> state;
    };
    std::vector<Saved> saved;
    auto hypothetical = [&](const std::map<int, std::vector<int>>& src, const std::vector<int>& tg,
                            const std::vector<BranchMove>& mv) {
      for (size_t k = 0; k < tg.size(); ++k) {
        const ProduceNode& n = nodes_[tg[k]];
        saved.push_back({tg[k], n.psi, n.seconds, n.cpu_seconds, n.min_separation, n.grad, n.iterations, n.moved,
                         mv[k].moved, run_.final_state[tg[k]]});
      }
      apply_round(src, tg, mv, false);
    };
    const auto moved_last = moved_last_;
    const auto tried = tried_;
    const auto min_gain = min_gain_;
    std::vector<AheadJob> jobs;
    // Nodes whose status in the next round is not certain: the unknown ones and their neighbours.
    auto spread = [&](const std::set<int>& u) {
      std::set<int> v = u;
      for (int x : u) v.insert(neighbours_[x].begin(), neighbours_[x].end());
      return v;
    };
    hypothetical(sources, targets, moves);
    std::set<int> uncertain = spread(unknown);
    for (int r = round + 1; any_moved && r <= opt_.branch_rounds; ++r) {
      std::map<int, std::vector<int>> next = round_sources();
      load_source_states(next);
      std::vector<int> next_targets;
      std::vector<BranchMove> next_moves;
      std::set<int> not_solved;
      any_moved = false;
      for (const auto& [target, from] : next) {
        next_targets.push_back(target);
        next_moves.emplace_back();
        if (uncertain.count(target)) continue;
        BranchJob j = job(target, from, nodes_[target].psi - min_gain_.at(target));
        if (const BranchMove* m = solved(r, j)) {
          next_moves.back() = *m;
          any_moved |= m->moved;
        } else {
          not_solved.insert(target);
          jobs.push_back({r, std::move(j)});
        }
      }
      not_solved.insert(uncertain.begin(), uncertain.end());
      uncertain = spread(not_solved);
      hypothetical(next, next_targets, next_moves);
    }
    for (auto it = saved.rbegin(); it != saved.rend(); ++it) {
      ProduceNode& n = nodes_[it->node];
      n.psi = it->psi, n.seconds = it->seconds, n.cpu_seconds = it->cpu_seconds, n.min_separation = it->min_separation;
      n.grad = it->grad, n.iterations = it->iterations, n.moved = it->moved;
      if (it->state_changed) run_.final_state[it->node] = it->state;  // (states read back stay)
    }
    moved_last_ = moved_last;
    tried_ = tried;
    min_gain_ = min_gain;
    return jobs;
  }

  // Applied together, in node order: the round's result does not depend on the threads.
  // (record false: a look ahead, nothing written to the checkpoint.)
  void apply_round(const std::map<int, std::vector<int>>& sources, const std::vector<int>& targets,
                   const std::vector<BranchMove>& moves, bool record = true) {
    for (const auto& [target, from] : sources)
      for (int src : from) tried_.insert({target, src});
    moved_last_.clear();
    for (size_t k = 0; k < targets.size(); ++k) {
      ProduceNode& n = nodes_[targets[k]];
      const BranchMove& mv = moves[k];
      n.iterations += mv.iterations;
      n.seconds += mv.seconds;
      n.cpu_seconds += mv.cpu_seconds;
      if (!mv.moved) continue;
      n.psi = mv.psi;
      n.grad = mv.grad;
      n.moved = true;
      moved_last_.push_back(targets[k]);
      for (auto it = tried_.begin(); it != tried_.end();)
        it = it->first == targets[k] || it->second == targets[k] ? tried_.erase(it) : std::next(it);
      n.min_separation = mv.state->certificate.min_distance;
      run_.final_state[targets[k]] = mv.state;
      if (run_.ck && record) {
        CheckpointRecord rec = record_of(n, kLowerBranch);
        rec.has_state = true;
        rec.state = *mv.state;
        run_.append(rec);
      }
    }
  }

  ProduceRun& run_;
  const ProduceOptions& opt_;
  std::vector<ProduceNode>& nodes_;
  std::vector<std::vector<int>> neighbours_;
  std::vector<double> term_gain_;
  std::vector<int> moved_last_;
  // Per target of the current round: the gain its energy must make.
  std::map<int, double> min_gain_;
  // (target, source) pairs already tried that did not move the target: the same two states
  // give the same solve, so they are tried again only after one of the two has moved. (Not
  // checkpointed: a resumed run tries them once more, finds the same, and ends the same.)
  std::set<std::pair<int, int>> tried_;
  int round_moved_ = 0;
};

}  // namespace

BranchMove branch_solve(const ProduceRun& run, const Strain& s, double best,
                        const std::vector<std::shared_ptr<const RveState>>& sources) {
  BranchMove mv;
  // A neighbour's branch is one grid step away: a solve that needs more than a few dozen
  // Newton iterations from there (the basket's hard corners crawl for hundreds) is not
  // continuing that branch, and is given up (measured on the basket, quick preset: the
  // late rounds' few nodes took 10 s each with the full budget and a 4-step retry).
  SolveOptions pass_solve = run.opt.solve;
  pass_solve.max_iterations = std::min(pass_solve.max_iterations, 40);
  for (const auto& src : sources) {
    if (!src) continue;
    // From the neighbour's equilibrium straight to this node's strain.
    RveState y = *src;
    const DensityResult r = energy_density(run.rve(), s, y, pass_solve);
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
  return mv;
}

std::vector<BranchJob> first_round_ahead(ProduceRun& run, const std::vector<bool>& complete) {
  if (!(run.opt.warm_start && run.opt.branch_rounds > 0) || run.rep.branch_rounds > 0) return {};
  return BranchPass(run).first_round(complete);
}

void branch_pass(ProduceRun& run) {
  if (run.opt.warm_start && run.opt.branch_rounds > 0) BranchPass(run).run();
}

}  // namespace yarnhom::yarn
