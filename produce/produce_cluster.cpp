// produce() on MPI ranks (docs/produce.md, "On a cluster"), rank 0's coordinator: it reads and
// writes the checkpoint, hands out the first pass's work (pieces of the sectors' warm-start
// trees, each ready once the node it starts from is solved; the longest path first, a rank that
// finishes early takes the next) and then the branch rounds' jobs, takes every finished node in
// as it comes (checkpoint record, progress line), and writes the one dataset. Every rank solves,
// rank 0 too, on a thread beside the coordinator (produce_cluster.hpp, cluster_solver.cpp).
//
// The branch rounds overlap: while a round's last jobs run, the ranks left without work solve
// the jobs of the next rounds that the finished ones already decide (BranchPredict,
// produce_pass.hpp; several rounds deep where those are solved ahead too), and each round,
// formed exactly as in one process, takes such a result only where it asks the very same job
// (target, threshold and source states). A job's result depends only on those, so the dataset is
// the one-process dataset, bit for bit, at any number of ranks; a killed run resumes from rank
// 0's checkpoint with any other.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <deque>
#include <map>
#include <numeric>
#include <set>

#include "core/cluster.hpp"
#include "produce/produce_cluster.hpp"

namespace yarnhom::yarn {
namespace {

using namespace cluster_produce;

CheckpointRecord state_record(const ProduceNode& n, const RveState& st) {
  CheckpointRecord rec = record_of(n, n.status);
  rec.has_state = true;
  rec.state = st;
  return rec;
}

class Coordinator {
 public:
  explicit Coordinator(ProduceRun& run)
      : run_(run), ranks_(cluster::size()), idle_(cluster::size(), false), load_(cluster::size()) {
    // Hand-out order: rank 0 last, as its solver shares a core with this thread.
    for (int r = 1; r < ranks_; ++r) order_.push_back(r);
    order_.push_back(0);
  }

  void run() {
    const double cpu0 = thread_cpu_seconds(), t0 = run_.elapsed();
    local_ = std::make_unique<LocalSolver>(run_);
    idle_[0] = true;
    first_pass();
    const double t1 = run_.elapsed();
    run_.branch_round = [this](int round, const std::vector<BranchJob>& jobs, const BranchPredict& next) {
      return branch_round(round, jobs, next);
    };
    branch_pass(run_);
    // Jobs solved ahead for a round that never came: their ranks finish them first.
    while (idle_count() < ranks_) handle(next_message());
    for (const auto& [key, id] : ahead_) lose(jobs_.at(id));
    for (int r = 1; r < ranks_; ++r) cluster::send(r, kToWorker, Pack(kStop).b);
    local_.reset();
    ProduceReport& rep = run_.rep;
    rep.node_pass_seconds = t1 - t0;
    rep.branch_pass_seconds = run_.elapsed() - t1;
    rep.coordinator_cpu_seconds = thread_cpu_seconds() - cpu0;
    rep.rank_load = load_;
    rep.ahead_solved = ahead_solved_;
    rep.ahead_used = ahead_used_;
  }

 private:
  // A piece of a sector's warm-start tree: a subtree of about unit_size nodes still to solve,
  // which can start once the node its root starts from (its parent, in another unit) is solved.
  // A sector chain alone is up to 120 nodes at the paper preset, too coarse for many ranks; the
  // pieces keep every rank busy while the order of each node's own start is unchanged.
  struct Unit {
    int task = 0, root = 0, parent = -1;  // local indices in the task's plan
    std::vector<int> nodes;               // local indices
    int height = 0;                       // nodes to solve on the longest path down from its root
  };
  // A branch job: of the round running (k: its index there), solved ahead for the next one, or
  // no longer wanted (its parts' results are dropped).
  enum class Use { kRound, kAhead, kDropped };
  struct Job {
    BranchJob in;
    Use use = Use::kRound;
    size_t k = 0;
    BranchMove combined;            // solved ahead: its move, once every part is in
    std::vector<BranchMove> part;   // by source
    std::vector<int> part_rank;     // the rank it went to (-1: none yet)
    std::vector<double> part_busy;  // its solve's seconds there
    int left = 0, out = 0;          // parts not finished; parts on the ranks
  };

  // ---- messages ----

  // The next message from any rank: rank 0's own solver's at once, the others' within a ms.
  cluster::Message next_message() {
    cluster::Message m;
    m.tag = kToRoot;
    for (;;) {
      if (local_->outbox.pop(m.bytes, 0)) return m.source = 0, m;
      if (cluster::try_receive(-1, kToRoot, m)) return m;
      if (local_->outbox.pop(m.bytes, 1)) return m.source = 0, m;
    }
  }

  void post(int rank, const std::string& bytes) {
    idle_[rank] = false;
    if (rank == 0) local_->inbox.push(bytes);
    else cluster::send(rank, kToWorker, bytes);
  }

  int idle_count() const { return int(std::count(idle_.begin(), idle_.end(), true)); }

  void handle(const cluster::Message& m) {
    Unpack in{m.bytes};
    switch (m.bytes.empty() ? 0 : m.bytes[0]) {
      case kHello: {
        const std::string sig = in.bytes(), mine = rest_signature(run_.r0.psi, run_.rest());
        if (sig != mine)
          cluster::abort("rank " + std::to_string(m.source) + " relaxed another rest state (" + sig + " against rank 0's " +
                         mine + "): the ranks run different builds of yarnhom, or different inputs");
        idle_[m.source] = true;
        break;
      }
      case kReady:
        --units_out_;
        load_[m.source].node_busy += in.get<double>();
        ++load_[m.source].tasks;
        idle_[m.source] = true;
        break;
      case kNode: node_finished(in.bytes()); break;
      case kMove: move_arrived(m.source, in); break;
      case kError: cluster::abort("rank " + std::to_string(m.source) + " failed: " + in.bytes()); break;
      default: cluster::abort("produce: an unexpected message from rank " + std::to_string(m.source));
    }
  }

  // ---- the first pass ----

  void first_pass() {
    tasks_ = sector_tasks(run_);
    mark_states_needed(run_, tasks_);
    for (const auto& n : run_.nodes) {
      ++total_;
      if (n.done) ++done_;
    }
    run_.final_state.assign(run_.nodes.size(), nullptr);
    make_units();
    // The terms whose nodes are all solved: their first branch round may start on ranks that the
    // warm-start trees' last paths leave idle.
    term_todo_.assign(run_.term_nodes_idx.size(), 0);
    for (const auto& n : run_.nodes) term_todo_[n.term] += !n.done;
    terms_changed_ = true;
    for (;;) {
      for (int r : order_) {
        if (!idle_[r]) continue;
        if (!ready_.empty()) {
          give_unit(r);
          continue;
        }
        if (terms_changed_) {
          terms_changed_ = false;
          std::vector<bool> complete(term_todo_.size());
          for (size_t t = 0; t < term_todo_.size(); ++t) complete[t] = term_todo_[t] == 0;
          std::vector<AheadJob> first;
          for (BranchJob& j : first_round_ahead(run_, complete)) first.push_back({1, std::move(j)});
          set_later(std::move(first));
        }
        if (!give_ahead(r)) break;
      }
      if (ready_.empty() && waiting_ == 0 && units_out_ == 0) break;
      handle(next_message());
    }
    later_.clear();
    // The longest chain of warm starts: no number of ranks makes the first pass shorter.
    for (const SectorTask& task : tasks_) {
      std::vector<double> path(task.nodes.size(), 0.0);
      for (int li : task.plan.order) {
        const int p = task.plan.parent[li];
        path[li] = run_.nodes[task.nodes[li]].seconds + (p >= 0 ? path[p] : 0.0);
        run_.rep.node_critical_seconds = std::max(run_.rep.node_critical_seconds, path[li]);
      }
    }
  }

  void make_units() {
    int todo_total = 0;
    for (const auto& n : run_.nodes) todo_total += !n.done;
    const int unit_size = std::max(4, todo_total / std::max(1, 8 * ranks_));
    for (size_t t = 0; t < tasks_.size(); ++t) {
      const SectorTask& task = tasks_[t];
      const WarmStartPlan& plan = task.plan;
      const int n = int(task.nodes.size());
      std::vector<int> acc(n, 0), height(n, 0), unit_of(n, -1);
      std::vector<bool> cut(n, false);
      for (auto it = plan.order.rbegin(); it != plan.order.rend(); ++it) {
        const int li = *it, todo = !run_.nodes[task.nodes[li]].done;
        acc[li] += todo;
        height[li] += todo;
        cut[li] = plan.parent[li] < 0 || acc[li] >= unit_size;
        const int p = plan.parent[li];
        if (p >= 0) {
          if (!cut[li]) acc[p] += acc[li];
          height[p] = std::max(height[p], height[li]);
        }
      }
      for (int li : plan.order) {
        if (cut[li]) {
          unit_of[li] = int(units_.size());
          units_.push_back({int(t), li, plan.parent[li], {}, height[li]});
        } else {
          unit_of[li] = unit_of[plan.parent[li]];
        }
        units_[unit_of[li]].nodes.push_back(li);
      }
    }
    for (size_t u = 0; u < units_.size(); ++u) {
      const Unit& unit = units_[u];
      int todo = 0;
      for (int li : unit.nodes) todo += !run_.nodes[tasks_[unit.task].nodes[li]].done;
      if (todo == 0) continue;
      const int parent_id = unit.parent >= 0 ? tasks_[unit.task].nodes[unit.parent] : -1;
      if (parent_id < 0 || run_.nodes[parent_id].done) {
        ready_.insert({-unit.height, int(u)});
      } else {
        waiting_for_[parent_id].push_back(int(u));
        ++waiting_;
      }
    }
  }

  // A resumed node's state (with its sensitivities) from the checkpoint, as record bytes.
  std::string resumed_record(const ProduceNode& n) {
    CheckpointRecord rec = run_.cc.records[n.record];
    try {
      read_checkpoint_state(run_.opt.checkpoint, run_.rest(), rec);
    } catch (const std::exception& e) {
      // One process would solve the node again in line; here its unit may be gone already.
      cluster::abort(std::string("the checkpoint changed while the run read it (") + e.what() +
                     "); run the same command again to resume from it");
    }
    return encode_record(rec, run_.rest());
  }

  void give_unit(int r) {
    const int u = ready_.begin()->second;
    ready_.erase(ready_.begin());
    const Unit& unit = units_[u];
    const SectorTask& task = tasks_[unit.task];
    std::vector<bool> in_unit(task.nodes.size(), false);
    for (int li : unit.nodes) in_unit[li] = true;
    std::vector<std::string> records;
    // What the unit's root starts from: its parent's state, solved in this run or resumed.
    if (unit.parent >= 0) {
      const int pid = task.nodes[unit.parent];
      auto it = solved_records_.find(pid);
      if (it != solved_records_.end()) records.push_back(it->second);
      else if (run_.nodes[pid].state_needed) records.push_back(resumed_record(run_.nodes[pid]));
    }
    // Resumed nodes inside the unit whose children are still to be solved.
    for (int li : unit.nodes) {
      ProduceNode& n = run_.nodes[task.nodes[li]];
      if (n.done && n.state_needed) records.push_back(resumed_record(n));
    }
    // Every node of the task outside the unit counts as done for the solver.
    std::vector<int> done_ids;
    for (size_t li = 0; li < task.nodes.size(); ++li)
      if (!in_unit[li] || run_.nodes[task.nodes[li]].done) done_ids.push_back(task.nodes[li]);
    Pack p(kTask);
    p.put(int32_t(unit.task)).put(uint64_t(done_ids.size()));
    for (int id : done_ids) p.put(int32_t(id));
    p.put(uint64_t(records.size()));
    for (const auto& rec : records) p.bytes(rec);
    ++units_out_;
    post(r, p.b);
  }

  void node_finished(const std::string& bytes) {
    const CheckpointRecord rec = decode_record(bytes, run_.rest());
    if (rec.term < 0 || rec.term >= int(run_.term_nodes_idx.size()) || rec.index < 0 ||
        rec.index >= int(run_.term_nodes_idx[rec.term].size()))
      cluster::abort("produce: a result for a node this run does not have");
    const int id = run_.term_nodes_idx[rec.term][rec.index];
    ProduceNode& n = run_.nodes[id];
    n.psi = n.psi1 = rec.psi;
    n.grad = n.grad1 = rec.grad;
    n.status = rec.status;
    n.iterations = rec.iterations;
    n.seconds = rec.seconds;
    n.cpu_seconds = rec.cpu_seconds;
    n.done = true;
    const bool ok = rec.status == "converged";
    if (ok) {
      n.min_separation = rec.min_distance;
      if (run_.opt.warm_start && run_.opt.branch_rounds > 0 && rec.has_state)
        run_.final_state[id] = std::make_shared<RveState>(rec.state);
    }
    ++done_;
    if (--term_todo_.at(n.term) == 0) terms_changed_ = true;
    if (!ok && rec.status == "topology_refused") ++run_.rep.refused;
    if (!ok) ++failed_;
    if (run_.ck) run_.append(rec);
    // Units that start from this node are ready now (with its state, when it converged).
    auto it = waiting_for_.find(id);
    if (it != waiting_for_.end()) {
      if (rec.has_state) solved_records_[id] = bytes;
      for (int u : it->second) ready_.insert({-units_[u].height, u});
      waiting_ -= int(it->second.size());
      waiting_for_.erase(it);
    }
    if (run_.opt.progress) run_.opt.progress(done_, total_, failed_, run_.elapsed());
  }

  // ---- the branch pass ----
  //
  // A job's sources are solved apart, one part each (a job with four sources would otherwise hold
  // its rank four solves long while the round waits on it), and combined in the sources' order
  // as branch_solve does: a part moves when its solve converged, certified, below the job's
  // threshold; the first part with the lowest energy wins, as the running threshold of one
  // process picks it.

  static bool same_job(const BranchJob& a, const BranchJob& b) {
    return a.target == b.target && std::memcmp(&a.best, &b.best, sizeof a.best) == 0 && a.from == b.from &&
           a.states == b.states;
  }

  using Part = std::pair<uint64_t, int>;  // (job, source)

  // A job's parts go to `queue` (none for a source without a state: nothing to solve).
  uint64_t new_job(const BranchJob& in, Use use, size_t k, std::deque<Part>& queue) {
    Job j;
    j.in = in;
    j.use = use;
    j.k = k;
    const size_t n = in.from.size();
    if (n > 255) cluster::abort("produce: a branch target with more than 255 sources");
    j.part.resize(n);
    j.part_rank.assign(n, -1);
    j.part_busy.assign(n, 0.0);
    for (size_t i = 0; i < n; ++i)
      if (in.states[i]) ++j.left, queue.push_back({next_id_, int(i)});
    if (j.left == 0) j.combined = combine(j);
    jobs_[next_id_] = std::move(j);
    return next_id_++;
  }

  BranchMove combine(const Job& j) const { return combine_sources(j.in.best, j.part); }

  // The next part still wanted from a queue.
  bool pop_part(std::deque<Part>& queue, Use use, Part& p) {
    while (!queue.empty()) {
      p = queue.front();
      queue.pop_front();
      auto it = jobs_.find(p.first);
      if (it != jobs_.end() && it->second.use == use) return true;
    }
    return false;
  }

  void send_part(int r, const Part& part) {
    Job& j = jobs_.at(part.first);
    const int i = part.second;
    j.part_rank[i] = r;
    ++j.out;
    Pack p(kTarget);
    p.put(uint64_t(part.first << 8 | uint64_t(i))).put(int32_t(j.in.target)).put(j.in.best).put(uint64_t(1));
    p.bytes(encode_record(state_record(run_.nodes[j.in.from[i]], *j.in.states[i]), run_.rest()));
    post(r, p.b);
  }

  // A result of the round running lands at its index; the order of the solves changes nothing.
  void finish(uint64_t id) {
    const Job& j = jobs_.at(id);
    round_moves_[j.k] = combine(j);
    have_[j.k] = true;
    ++finished_;
    moved_ += round_moves_[j.k].moved;
    changed_ = true;
    jobs_.erase(id);
    if (run_.opt.branch_progress)
      run_.opt.branch_progress(round_, finished_, int(round_moves_.size()), moved_, run_.elapsed());
  }

  void lose(const Job& j) {
    for (size_t i = 0; i < j.part.size(); ++i)
      if (j.part_rank[i] >= 0) load_[j.part_rank[i]].ahead_lost += j.part_busy[i];
  }

  void move_arrived(int source, Unpack& in) {
    const uint64_t tag = in.get<uint64_t>(), id = tag >> 8;
    const int i = int(tag & 255);
    const double busy = in.get<double>();
    auto it = jobs_.find(id);
    if (it == jobs_.end() || i >= int(it->second.part.size()))
      cluster::abort("produce: a branch result from rank " + std::to_string(source) + " for no job");
    Job& j = it->second;
    idle_[source] = true;
    load_[source].branch_busy += busy;
    ++load_[source].jobs;
    j.part[i] = move_of(decode_record(in.bytes(), run_.rest()));
    j.part_busy[i] = busy;
    if (j.use == Use::kRound) round_longest_ = std::max(round_longest_, busy);
    --j.out;
    --j.left;
    if (j.use == Use::kRound && j.left == 0) {
      finish(id);
    } else if (j.use == Use::kAhead && j.left == 0) {
      j.combined = combine(j);
      changed_ = true;  // a later round's look ahead may go deeper now
    } else if (j.use == Use::kDropped) {
      load_[source].ahead_lost += busy;
      if (j.out == 0) jobs_.erase(it);
    }
  }

  // The jobs that may be solved ahead of their round: handed out the earliest round first, then
  // the fewest sources. One solved ahead for the same round and target with other inputs (an
  // earlier look that the finished jobs have since corrected) is dropped.
  void set_later(std::vector<AheadJob> jobs) {
    std::vector<AheadJob> keep;
    for (AheadJob& a : jobs) {
      auto it = ahead_.find({a.round, a.job.target});
      if (it != ahead_.end()) {
        if (same_job(jobs_.at(it->second).in, a.job)) continue;
        drop(it->second);
        ahead_.erase(it);
      }
      keep.push_back(std::move(a));
    }
    std::stable_sort(keep.begin(), keep.end(), [](const AheadJob& a, const AheadJob& b) {
      return a.round != b.round ? a.round > b.round : a.job.from.size() < b.job.from.size();
    });
    later_ = std::move(keep);
  }

  void drop(uint64_t id) {
    Job& j = jobs_.at(id);
    j.use = Use::kDropped;
    lose(j);
    if (j.out == 0) jobs_.erase(id);
  }

  // A later round's job solved ahead with exactly these inputs: its move (null: none, or not all
  // its parts are in).
  const BranchMove* solved(int round, const BranchJob& in) const {
    auto it = ahead_.find({round, in.target});
    if (it == ahead_.end()) return nullptr;
    const Job& j = jobs_.at(it->second);
    return j.left == 0 && same_job(j.in, in) ? &j.combined : nullptr;
  }

  bool give_ahead(int r) {
    for (Part p;;) {
      if (pop_part(ahead_parts_, Use::kAhead, p)) {
        send_part(r, p);
        return true;
      }
      if (later_.empty()) return false;
      const AheadJob& a = later_.back();
      ahead_[{a.round, a.job.target}] = new_job(a.job, Use::kAhead, 0, ahead_parts_);
      later_.pop_back();
      ++ahead_solved_;
    }
  }

  std::vector<BranchMove> branch_round(int round, const std::vector<BranchJob>& jobs, const BranchPredict& next) {
    round_ = round;
    round_longest_ = 0;
    round_moves_.assign(jobs.size(), BranchMove{});
    have_.assign(jobs.size(), false);
    finished_ = moved_ = 0;
    // Jobs solved (or being solved) ahead: taken where this round asks exactly them.
    std::vector<size_t> queue;
    std::vector<uint64_t> complete;
    for (size_t k = 0; k < jobs.size(); ++k) {
      auto a = ahead_.find({round, jobs[k].target});
      if (a != ahead_.end() && same_job(jobs_.at(a->second).in, jobs[k])) {
        Job& j = jobs_.at(a->second);
        ++ahead_used_;
        for (double b : j.part_busy) round_longest_ = std::max(round_longest_, b);
        j.use = Use::kRound;
        j.k = k;
        if (j.left == 0) complete.push_back(a->second);
        ahead_.erase(a);
      } else {
        queue.push_back(k);
      }
    }
    for (uint64_t id : complete) finish(id);
    // Those solved for this round that it did not ask (those of later rounds wait for theirs).
    for (auto it = ahead_.begin(); it != ahead_.end();) {
      if (it->first.first > round) break;
      drop(it->second);
      it = ahead_.erase(it);
    }
    // The parts of the adopted jobs not handed out yet come first in this round's queue; those of
    // later rounds' jobs stay where they are.
    round_parts_.clear();
    std::deque<Part> later_parts;
    for (const Part& p : ahead_parts_) {
      auto it = jobs_.find(p.first);
      if (it == jobs_.end()) continue;
      if (it->second.use == Use::kRound) round_parts_.push_back(p);
      else if (it->second.use == Use::kAhead) later_parts.push_back(p);
    }
    ahead_parts_ = std::move(later_parts);
    // Then the jobs with the most sources first, so that the round does not end on one of them.
    std::stable_sort(queue.begin(), queue.end(),
                     [&](size_t a, size_t b) { return jobs[a].from.size() > jobs[b].from.size(); });
    for (size_t k : queue) {
      const uint64_t id = new_job(jobs[k], Use::kRound, k, round_parts_);
      if (jobs_.at(id).left == 0) finish(id);
    }
    later_.clear();
    changed_ = true;
    while (finished_ < int(jobs.size())) {
      for (int r : order_) {
        if (!idle_[r]) continue;
        Part p;
        if (pop_part(round_parts_, Use::kRound, p) || pop_part(ahead_parts_, Use::kAhead, p)) {
          send_part(r, p);
          continue;
        }
        // What the finished jobs decide of the next round, anew once those decided before are
        // handed out, and not more than a fifth of the time (each look costs some milliseconds
        // at the paper preset, while the other ranks' results wait).
        if (changed_ && later_.empty() && run_.elapsed() >= next_look_) {
          changed_ = false;
          std::vector<const BranchMove*> known(jobs.size(), nullptr);
          for (size_t k = 0; k < jobs.size(); ++k)
            if (have_[k]) known[k] = &round_moves_[k];
          const double t0 = run_.elapsed();
          set_later(next(known, [this](int r, const BranchJob& in) { return solved(r, in); }));
          next_look_ = run_.elapsed() + 4 * (run_.elapsed() - t0);
        }
        if (!give_ahead(r)) break;
      }
      if (finished_ < int(jobs.size())) handle(next_message());
    }
    run_.rep.branch_critical_seconds += round_longest_;
    return round_moves_;
  }

  ProduceRun& run_;
  const int ranks_;
  std::vector<int> order_;
  std::vector<bool> idle_;  // by rank
  std::vector<RankLoad> load_;
  std::unique_ptr<LocalSolver> local_;
  // The first pass.
  std::vector<SectorTask> tasks_;
  std::vector<Unit> units_;
  std::set<std::pair<int, int>> ready_;             // (-height, unit): the longest path first
  std::map<int, std::vector<int>> waiting_for_;     // node id -> units whose root starts from it
  int waiting_ = 0;
  std::map<int, std::string> solved_records_;       // those nodes' records, with their states
  int total_ = 0, done_ = 0, failed_ = 0;
  int units_out_ = 0;               // units on the ranks
  std::vector<int> term_todo_;      // nodes still to solve, by term
  bool terms_changed_ = false;      // a term's last node came in since the look ahead
  // The branch pass: jobs on the ranks by id, those solved ahead by target, the round running.
  std::map<uint64_t, Job> jobs_;
  uint64_t next_id_ = 0;
  std::map<std::pair<int, int>, uint64_t> ahead_;  // (round, target) -> job solved ahead
  std::vector<AheadJob> later_;     // later rounds' jobs that may be solved ahead
  std::deque<Part> round_parts_, ahead_parts_;  // parts to hand out
  int round_ = 0, finished_ = 0, moved_ = 0;
  double round_longest_ = 0;  // the round's longest solve (of one source)
  std::vector<BranchMove> round_moves_;
  std::vector<bool> have_;
  bool changed_ = false;  // a result came in since the look ahead
  double next_look_ = 0;  // the earliest time of the next look ahead (run.elapsed())
  int ahead_solved_ = 0, ahead_used_ = 0;
};

}  // namespace

void cluster_coordinate(ProduceRun& run) { Coordinator(run).run(); }

}  // namespace yarnhom::yarn
