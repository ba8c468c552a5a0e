#include "pipeline/rank_tasks.hpp"

#include <fcntl.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/cluster.hpp"
#include "core/console.hpp"
#include "pipeline/stage_runner.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

namespace {

// Tags of this protocol's messages (produce's are others; one command runs at a time anyway).
constexpr int kToRoot = 41, kToWorker = 42, kEnd = 43;

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Rank 0: hands out the tasks, runs some itself, prints the progress.
class Root {
 public:
  Root(const RankTasks& g, FILE* out, const std::string& what)
      : t_(g.tasks()), out_(out), what_(what), prio_(t_.size(), 0), state_(t_.size(), 0), workers_(cluster::size() - 1) {
    // A task's priority: its weight plus that of the heaviest chain of tasks that wait for it
    // (`after` names earlier tasks only, so one backward sweep).
    for (size_t j = t_.size(); j-- > 0;) {
      prio_[j] += t_[j].weight;
      for (int i : t_[j].after) prio_[size_t(i)] = std::max(prio_[size_t(i)], prio_[j]);
      total_ += t_[j].weight;
    }
  }

  void run() {
    std::fprintf(out_, "%s on %d ranks: %zu tasks (pieces of the rows; a stage shared by rows runs once), each rank's stage "
                 "lines in logs/rank-R.log\n", what_.c_str(), cluster::size(), t_.size());
    std::fflush(out_);
    set_stage_wait_hook([this] { service(); });
    while (done_ < t_.size() || heard_ < workers_) {
      service();
      const int k = done_ < t_.size() ? next() : -1;
      if (k < 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        continue;
      }
      start(k, 0);
      const auto t0 = std::chrono::steady_clock::now();
      t_[size_t(k)].run();
      finish(k, 0, since(t0));
    }
    set_stage_wait_hook(nullptr);
    for (int w = 1; w <= workers_; ++w) cluster::send(w, kToWorker, "stop");
    std::fprintf(out_, "[%s] every task done; rank 0 measures and writes the tables\n", format_seconds(since(t0_)).c_str());
    std::fflush(out_);
  }

 private:
  // The ready task of the highest priority (the earliest of equals), -1 when none.
  int next() const {
    int best = -1;
    for (size_t k = 0; k < t_.size(); ++k) {
      if (state_[k] != 0) continue;
      bool ready = true;
      for (int i : t_[k].after) ready = ready && state_[size_t(i)] == 2;
      if (ready && (best < 0 || prio_[k] > prio_[size_t(best)])) best = int(k);
    }
    return best;
  }

  void start(int k, int rank) {
    state_[size_t(k)] = 1;
    std::fprintf(out_, "[%s] rank %d: %s\n", format_seconds(since(t0_)).c_str(), rank, t_[size_t(k)].label.c_str());
    std::fflush(out_);
  }

  void finish(int k, int rank, double seconds) {
    state_[size_t(k)] = 2;
    ++done_;
    done_weight_ += t_[size_t(k)].weight;
    const double el = since(t0_);
    std::string eta;
    if (done_ < t_.size() && done_weight_ > 0)
      eta = ", ETA " + format_seconds(el / done_weight_ * std::max(0.0, total_ - done_weight_)) + " at the pace so far";
    std::fprintf(out_, "[%s] rank %d done in %s: %s (%zu of %zu tasks%s)\n", format_seconds(el).c_str(), rank,
                 format_seconds(seconds).c_str(), t_[size_t(k)].label.c_str(), done_, t_.size(), eta.c_str());
    std::fflush(out_);
  }

  // Reads what the workers sent and hands out what is ready.
  void service() {
    cluster::Message m;
    while (cluster::try_receive(-1, kToRoot, m)) {
      std::istringstream in(m.bytes);
      std::string kind;
      in >> kind;
      if (kind == "ready") {
        ++heard_;
      } else if (kind == "done") {
        int k = -1;
        double s = 0;
        in >> k >> s;
        if (k < 0 || size_t(k) >= t_.size() || state_[size_t(k)] != 1)
          cluster::abort("a report of a task this run did not hand out, from rank " + std::to_string(m.source));
        finish(k, m.source, s);
      } else {
        cluster::abort("an unexpected message from rank " + std::to_string(m.source) + ": " + m.bytes);
      }
      idle_.push_back(m.source);
    }
    for (int k; !idle_.empty() && (k = next()) >= 0; idle_.pop_front()) {
      start(k, idle_.front());
      cluster::send(idle_.front(), kToWorker, "task " + std::to_string(k) + " " + stage_run_id());
    }
  }

  const std::vector<RankTask>& t_;
  FILE* out_;
  std::string what_;
  std::vector<double> prio_;
  std::vector<int> state_;  // 0 waiting, 1 running, 2 done
  int workers_, heard_ = 0;
  size_t done_ = 0;
  double total_ = 0, done_weight_ = 0;
  std::deque<int> idle_;
  const std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

void worker(const RankTasks& g) {
  cluster::send(0, kToRoot, "ready");
  for (;;) {
    const cluster::Message m = cluster::receive(0, kToWorker, 20);
    std::istringstream in(m.bytes);
    std::string kind, id;
    int k = -1;
    in >> kind >> k >> id;
    if (kind == "stop") break;
    if (kind != "task" || k < 0 || size_t(k) >= g.tasks().size())
      throw std::runtime_error("an unexpected message from rank 0: " + m.bytes);
    set_stage_run_id(id);
    const auto t0 = std::chrono::steady_clock::now();
    g.tasks()[size_t(k)].run();
    std::fflush(stdout);
    char done[64];
    std::snprintf(done, sizeof done, "done %d %.3f", k, since(t0));
    cluster::send(0, kToRoot, done);
  }
}

}  // namespace

int RankTasks::add(const std::string& key, const std::string& label, double weight, const std::vector<int>& after,
                   std::function<void()> run) {
  for (size_t k = 0; k < tasks_.size(); ++k)
    if (tasks_[k].key == key) return int(k);
  RankTask t{key, label, weight, {}, std::move(run)};
  for (int i : after)
    if (i >= 0) t.after.push_back(i);
  tasks_.push_back(std::move(t));
  return int(tasks_.size()) - 1;
}

namespace {

int own_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  return ::sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : 1;
}

int node_share() { return int(std::max(1L, ::sysconf(_SC_NPROCESSORS_ONLN)) / std::max(1, cluster::node_size())); }

}  // namespace

int threads_per_rank() { return std::max(1, std::min(own_cpus(), node_share())); }

OnRanks::OnRanks(const fs::path& dir, const std::string& what, const std::function<void(RankTasks&)>& build) {
  if (cluster::size() <= 1) return;
  several_ = true;
  RankTasks g;
  build(g);
  if (!std::getenv("OMP_NUM_THREADS")) ::setenv("OMP_NUM_THREADS", std::to_string(threads_per_rank()).c_str(), 1);
  // Each rank's stage lines go to its own log; rank 0 keeps the terminal for the progress.
  fs::create_directories(dir / "logs");
  const std::string log = (dir / "logs" / ("rank-" + std::to_string(cluster::rank()) + ".log")).string();
  std::fflush(stdout);
  const int saved = ::dup(1), fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (saved < 0 || fd < 0) throw std::runtime_error("cannot write " + log + ": " + std::strerror(errno));
  ::dup2(fd, 1);
  ::close(fd);
  std::printf("== %s, %s, the stages' threads: %s\n", what.c_str(), cluster::where().c_str(), std::getenv("OMP_NUM_THREADS"));
  std::fflush(stdout);
  if (cluster::rank() == 0) {
    FILE* out = ::fdopen(::dup(saved), "w");
    if (!out) throw std::runtime_error("cannot write the progress");
    std::fprintf(out, "each rank's stages: %s thread(s) by default (OMP_NUM_THREADS)\n", std::getenv("OMP_NUM_THREADS"));
    if (own_cpus() < node_share())
      std::fprintf(out, "  (mpirun bound rank 0 to %d CPU(s) of the %d per rank on its node, and its stages with it: "
                   "add --bind-to none, or --map-by slot:PE=C for C cores per rank)\n", own_cpus(), node_share());
    Root(g, out, what).run();
    std::fclose(out);
    std::fflush(stdout);
    ::dup2(saved, 1);
    ::close(saved);
    return;
  }
  ::close(saved);
  worker(g);
  root_ = false;
  cluster::receive(0, kEnd, 100);  // rank 0's single pass
}

OnRanks::~OnRanks() {
  if (!several_ || !root_) return;
  try {
    for (int w = 1; w < cluster::size(); ++w) cluster::send(w, kEnd, "end");
  } catch (...) {
  }
}

}  // namespace yarnhom::pipeline
