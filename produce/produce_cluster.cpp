// produce() on MPI ranks (docs/produce.md, "On a cluster"): rank 0 coordinates, every other rank
// solves. Rank 0 reads and writes the checkpoint, hands out the first pass's work (pieces of the
// sectors' warm-start trees, each ready once the node it starts from is solved; the longest
// path first, a rank that finishes early takes the next) and then each branch round's targets
// one at a time, takes every finished node in as it comes (checkpoint record, progress
// line), and writes the one dataset. The workers build the same nodes and tasks from the same
// options and relax the same rest tile (checked: each sends its rest signature first), so a
// node's solve does not depend on where it runs, and the dataset is the one-process dataset, bit
// for bit, at any number of ranks; a killed run resumes from rank 0's checkpoint with any other.
//
// Messages (core/cluster.hpp), one byte of kind first; worker -> rank 0 all on one tag, so that
// each worker's messages arrive in the order it sent them:
//   hello  <rest signature>                 a worker is ready, with its rest state's identity
//   node   <checkpoint record>              a first-pass node finished (its state when converged)
//   ready                                   a worker finished its task
//   move   <k> <record>                     branch target k solved (its state when it moved)
//   error  <text>                           a worker failed; rank 0 ends the run
// rank 0 -> a worker:
//   task   <task> <done ids> <records>      solve this sector's nodes not listed done; the records
//                                           are the states its nodes start from (solved elsewhere
//                                           or resumed)
//   target <k> <node> <best> <records>      solve node from each record's state, accept below best
//   stop
#include <algorithm>
#include <cstring>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>

#include "core/cluster.hpp"
#include "produce/produce_pass.hpp"

namespace yarnhom::yarn {
namespace {

constexpr int kToRoot = 1, kToWorker = 2;
enum Kind : char { kHello = 'h', kNode = 'n', kReady = 'r', kMove = 'm', kError = 'e', kTask = 't', kTarget = 'g', kStop = 's' };

// Plain values and byte strings, length first.
struct Pack {
  std::string b;
  explicit Pack(Kind k) { b.push_back(k); }
  template <class T>
  Pack& put(const T& v) {
    b.append(reinterpret_cast<const char*>(&v), sizeof v);
    return *this;
  }
  Pack& bytes(const std::string& s) {
    put(static_cast<uint64_t>(s.size()));
    b += s;
    return *this;
  }
};
struct Unpack {
  const std::string& b;
  size_t at = 1;
  template <class T>
  T get() {
    if (at + sizeof(T) > b.size()) throw std::runtime_error("produce: a message cut short");
    T v;
    std::memcpy(&v, b.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
  std::string bytes() {
    const uint64_t n = get<uint64_t>();
    if (at + n > b.size()) throw std::runtime_error("produce: a message cut short");
    std::string s = b.substr(at, n);
    at += n;
    return s;
  }
};

CheckpointRecord state_record(const ProduceNode& n, const RveState& st) {
  CheckpointRecord rec = record_of(n, n.status);
  rec.has_state = true;
  rec.state = st;
  return rec;
}

// A branch target's result travels as a record: its state present when it moved.
CheckpointRecord move_record(const BranchMove& mv) {
  CheckpointRecord rec;
  rec.psi = mv.psi;
  rec.grad = mv.grad;
  rec.iterations = mv.iterations;
  rec.seconds = mv.seconds;
  rec.cpu_seconds = mv.cpu_seconds;
  rec.status = kLowerBranch;
  rec.has_state = mv.moved;
  if (mv.moved) rec.state = *mv.state;
  return rec;
}
BranchMove move_of(CheckpointRecord&& rec) {
  BranchMove mv;
  mv.moved = rec.has_state;
  mv.psi = rec.psi;
  mv.grad = rec.grad;
  mv.iterations = rec.iterations;
  mv.seconds = rec.seconds;
  mv.cpu_seconds = rec.cpu_seconds;
  if (mv.moved) mv.state = std::make_shared<RveState>(std::move(rec.state));
  return mv;
}

// ---- rank 0 ----------------------------------------------------------------------------------

class Coordinator {
 public:
  explicit Coordinator(ProduceRun& run) : run_(run), workers_(cluster::size() - 1), idle_(cluster::size(), false) {}

  void first_pass() {
    tasks_ = sector_tasks(run_);
    mark_states_needed(run_, tasks_);
    for (const auto& n : run_.nodes) {
      ++total_;
      if (n.done) ++done_;
    }
    run_.final_state.assign(run_.nodes.size(), nullptr);
    make_units();
    while (!ready_.empty() || waiting_ > 0 || idle_count() < workers_) handle(cluster::receive(-1, kToRoot, 1));
    run_.branch_round = [this](int round, const std::vector<int>& targets, const std::vector<double>& best,
                               const std::vector<std::vector<int>>& from) { return branch_round(round, targets, best, from); };
  }

  void stop() {
    for (int w = 1; w <= workers_; ++w) cluster::send(w, kToWorker, Pack(kStop).b);
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

  void make_units() {
    int todo_total = 0;
    for (const auto& n : run_.nodes) todo_total += !n.done;
    const int unit_size = std::max(4, todo_total / std::max(1, 8 * workers_));
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
      case kReady: idle_[m.source] = true; break;
      case kNode: node_finished(in.bytes()); break;
      case kError: cluster::abort("rank " + std::to_string(m.source) + " failed: " + in.bytes()); break;
      default: cluster::abort("produce: an unexpected message from rank " + std::to_string(m.source));
    }
    for (int w = 1; w <= workers_ && !ready_.empty(); ++w)
      if (idle_[w]) give_unit(w);
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

  void give_unit(int w) {
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
    // Every node of the task outside the unit counts as done for the worker.
    std::vector<int> done_ids;
    for (size_t li = 0; li < task.nodes.size(); ++li)
      if (!in_unit[li] || run_.nodes[task.nodes[li]].done) done_ids.push_back(task.nodes[li]);
    Pack p(kTask);
    p.put(int32_t(unit.task)).put(uint64_t(done_ids.size()));
    for (int id : done_ids) p.put(int32_t(id));
    p.put(uint64_t(records.size()));
    for (const auto& r : records) p.bytes(r);
    idle_[w] = false;
    cluster::send(w, kToWorker, p.b);
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

  std::vector<BranchMove> branch_round(int round, const std::vector<int>& targets, const std::vector<double>& best,
                                       const std::vector<std::vector<int>>& from) {
    std::vector<BranchMove> moves(targets.size());
    // The targets with the most sources (one solve each) first, so that the round does not wait
    // on a long one handed out last; each result lands at its own index, so the order of the
    // solves changes nothing in the data.
    std::vector<size_t> order(targets.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return from[a].size() > from[b].size(); });
    size_t next = 0;
    int finished = 0, moved = 0;
    auto send_target = [&](int w) {
      const size_t k = order[next++];
      Pack p(kTarget);
      p.put(uint64_t(k)).put(int32_t(targets[k])).put(best[k]);
      std::vector<std::string> records;
      for (int src : from[k])
        if (run_.final_state[src]) records.push_back(encode_record(state_record(run_.nodes[src], *run_.final_state[src]), run_.rest()));
      p.put(uint64_t(records.size()));
      for (const auto& r : records) p.bytes(r);
      idle_[w] = false;
      cluster::send(w, kToWorker, p.b);
    };
    for (int w = 1; w <= workers_ && next < targets.size(); ++w) send_target(w);
    while (finished < int(targets.size())) {
      const cluster::Message m = cluster::receive(-1, kToRoot, 1);
      Unpack in{m.bytes};
      if (m.bytes.empty() || m.bytes[0] != kMove) {
        handle(m);  // an error
        continue;
      }
      const uint64_t k = in.get<uint64_t>();
      BranchMove& mv = moves.at(k);
      mv = move_of(decode_record(in.bytes(), run_.rest()));
      ++finished;
      moved += mv.moved;
      if (run_.opt.branch_progress)
        run_.opt.branch_progress(round, finished, int(targets.size()), moved, run_.elapsed());
      if (next < targets.size()) send_target(m.source);
      else idle_[m.source] = true;
    }
    return moves;
  }

  ProduceRun& run_;
  const int workers_;
  std::vector<bool> idle_;  // by rank
  std::vector<SectorTask> tasks_;
  std::vector<Unit> units_;
  std::set<std::pair<int, int>> ready_;             // (-height, unit): the longest path first
  std::map<int, std::vector<int>> waiting_for_;     // node id -> units whose root starts from it
  int waiting_ = 0;
  std::map<int, std::string> solved_records_;       // those nodes' records, with their states
  int total_ = 0, done_ = 0, failed_ = 0;
};

// ---- the other ranks -------------------------------------------------------------------------

class Worker {
 public:
  explicit Worker(ProduceRun& run) : run_(run) {
    run_.node_sink = [&run](const CheckpointRecord& rec) {
      cluster::send(0, kToRoot, Pack(kNode).bytes(encode_record(rec, run.rest())).b);
    };
  }

  void run() {
    cluster::send(0, kToRoot, Pack(kHello).bytes(rest_signature(run_.r0.psi, run_.rest())).b);
    tasks_ = sector_tasks(run_);
    for (;;) {
      const cluster::Message m = cluster::receive(0, kToWorker);
      Unpack in{m.bytes};
      const char kind = m.bytes.empty() ? 0 : m.bytes[0];
      if (kind == kStop) return;
      if (kind == kTask) task(in);
      else if (kind == kTarget) target(in);
      else throw std::runtime_error("an unexpected message from rank 0");
    }
  }

 private:
  void task(Unpack& in) {
    const int t = in.get<int32_t>();
    if (t < 0 || t >= int(tasks_.size())) throw std::runtime_error("a task this rank does not have");
    const SectorTask& task = tasks_[t];
    for (int id : task.nodes) run_.nodes[id].done = run_.nodes[id].state_needed = false;
    const uint64_t nd = in.get<uint64_t>();
    for (uint64_t i = 0; i < nd; ++i) run_.nodes.at(in.get<int32_t>()).done = true;
    run_.resumed_states.clear();
    const uint64_t nr = in.get<uint64_t>();
    for (uint64_t i = 0; i < nr; ++i) {
      CheckpointRecord rec = decode_record(in.bytes(), run_.rest());
      const int id = run_.term_nodes_idx.at(rec.term).at(rec.index);
      run_.nodes[id].state_needed = true;
      run_.resumed_states[id] = std::move(rec);
    }
    if (!have_sensitivity_) rest_sens_ = rest_sensitivity(run_), have_sensitivity_ = true;
    int done = 0, failed = 0;
    solve_task(run_, task, rest_sens_, done, failed, 0);
    run_.resumed_states.clear();
    cluster::send(0, kToRoot, Pack(kReady).b);
  }

  void target(Unpack& in) {
    const uint64_t k = in.get<uint64_t>();
    const int id = in.get<int32_t>();
    const double best = in.get<double>();
    std::vector<std::shared_ptr<const RveState>> from;
    const uint64_t nr = in.get<uint64_t>();
    for (uint64_t i = 0; i < nr; ++i)
      from.push_back(std::make_shared<RveState>(decode_record(in.bytes(), run_.rest()).state));
    const BranchMove mv = branch_solve(run_, run_.nodes.at(id).s, best, from);
    cluster::send(0, kToRoot, Pack(kMove).put(k).bytes(encode_record(move_record(mv), run_.rest())).b);
  }

  ProduceRun& run_;
  std::vector<SectorTask> tasks_;
  std::vector<Eigen::VectorXd> rest_sens_;
  bool have_sensitivity_ = false;
};

}  // namespace

void cluster_coordinate(ProduceRun& run) {
  Coordinator c(run);
  c.first_pass();
  branch_pass(run);
  c.stop();
}

void cluster_work(ProduceRun& run) {
  try {
    Worker(run).run();
  } catch (const std::exception& e) {
    cluster::send(0, kToRoot, Pack(kError).bytes(cluster::where() + ": " + e.what()).b);
    // Rank 0 ends the run (MPI_Abort); wait for it.
    cluster::receive(0, kToWorker);
  }
}

}  // namespace yarnhom::yarn
