// produce() on MPI ranks, the solving side (produce_cluster.hpp): every rank but 0 runs a solver
// on its main thread; rank 0 runs one on a thread beside its coordinator (LocalSolver). A solver
// builds the same nodes and tasks as rank 0 from the same options and relaxes the same rest tile,
// so a node's solve does not depend on where it runs.
#include <omp.h>
#include <time.h>

#include <chrono>
#include <functional>

#include "core/cluster.hpp"
#include "produce/produce_cluster.hpp"

namespace yarnhom::yarn::cluster_produce {

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

BranchMove combine_sources(double best, const std::vector<BranchMove>& parts) {
  BranchMove mv;
  for (const BranchMove& p : parts) {
    mv.seconds += p.seconds;
    mv.cpu_seconds += p.cpu_seconds;
    mv.iterations += p.iterations;
    if (p.moved && p.psi < best) {
      best = p.psi;
      mv.moved = true;
      mv.psi = p.psi;
      mv.grad = p.grad;
      mv.state = p.state;
    }
  }
  return mv;
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void Mailbox::push(std::string m) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    q_.push_back(std::move(m));
  }
  cv_.notify_one();
}

bool Mailbox::pop(std::string& m, int wait_ms) {
  std::unique_lock<std::mutex> lock(mu_);
  if (wait_ms < 0) cv_.wait(lock, [&] { return !q_.empty(); });
  else if (wait_ms > 0) cv_.wait_for(lock, std::chrono::milliseconds(wait_ms), [&] { return !q_.empty(); });
  if (q_.empty()) return false;
  m = std::move(q_.front());
  q_.pop_front();
  return true;
}

namespace {

// Solves what the coordinator sends; its answers go to `out`.
class Solver {
 public:
  Solver(ProduceRun& run, std::function<void(const std::string&)> out) : run_(run), out_(std::move(out)) {
    run_.node_sink = [this](const CheckpointRecord& rec) { out_(Pack(kNode).bytes(encode_record(rec, run_.rest())).b); };
    tasks_ = sector_tasks(run_);
  }

  // False once told to stop.
  bool handle(const std::string& m) {
    Unpack in{m};
    const char kind = m.empty() ? 0 : m[0];
    if (kind == kStop) return false;
    const auto t0 = std::chrono::steady_clock::now();
    auto busy = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    if (kind == kTask) {
      task(in);
      out_(Pack(kReady).put(busy()).b);
    } else if (kind == kTarget) {
      const uint64_t job = in.get<uint64_t>();
      const BranchMove mv = target(in);
      out_(Pack(kMove).put(job).put(busy()).bytes(encode_record(move_record(mv), run_.rest())).b);
    } else {
      throw std::runtime_error("an unexpected message from rank 0");
    }
    return true;
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
  }

  BranchMove target(Unpack& in) {
    const int id = in.get<int32_t>();
    const double best = in.get<double>();
    std::vector<std::shared_ptr<const RveState>> from;
    const uint64_t nr = in.get<uint64_t>();
    for (uint64_t i = 0; i < nr; ++i)
      from.push_back(std::make_shared<RveState>(decode_record(in.bytes(), run_.rest()).state));
    return branch_solve(run_, run_.nodes.at(id).s, best, from);
  }

  ProduceRun& run_;
  std::function<void(const std::string&)> out_;
  std::vector<SectorTask> tasks_;
  std::vector<Eigen::VectorXd> rest_sens_;
  bool have_sensitivity_ = false;
};

}  // namespace

LocalSolver::LocalSolver(const ProduceRun& run) : opt_(run.opt) {
  opt_.progress = nullptr;
  opt_.branch_progress = nullptr;
  run_ = std::make_unique<ProduceRun>(run.pattern, opt_, run.tile);
  run_->r0 = run.r0;
  make_nodes(*run_);
  thread_ = std::thread([this] {
    // A new thread starts with OpenMP's default thread count, not the one the run set.
    omp_set_num_threads(run_->threads);
    try {
      Solver solver(*run_, [this](const std::string& m) { outbox.push(m); });
      for (std::string m; inbox.pop(m, -1) && solver.handle(m);) {
      }
    } catch (const std::exception& e) {
      outbox.push(Pack(kError).bytes(std::string("its solving thread: ") + e.what()).b);  // (no MPI off the main thread)
    }
  });
}

LocalSolver::~LocalSolver() {
  inbox.push(Pack(kStop).b);
  thread_.join();
}

}  // namespace yarnhom::yarn::cluster_produce

namespace yarnhom::yarn {

void cluster_work(ProduceRun& run) {
  using namespace cluster_produce;
  try {
    Solver solver(run, [](const std::string& m) { cluster::send(0, kToRoot, m); });
    cluster::send(0, kToRoot, Pack(kHello).bytes(rest_signature(run.r0.psi, run.rest())).b);
    while (solver.handle(cluster::receive(0, kToWorker).bytes)) {
    }
  } catch (const std::exception& e) {
    cluster::send(0, kToRoot, Pack(kError).bytes(cluster::where() + ": " + e.what()).b);
    // Rank 0 ends the run (MPI_Abort); wait for it.
    cluster::receive(0, kToWorker);
  }
}

}  // namespace yarnhom::yarn
