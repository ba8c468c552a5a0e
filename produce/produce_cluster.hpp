#pragma once
// Internal to produce_cluster.cpp (rank 0's coordinator) and cluster_solver.cpp (the solving
// side, on every rank): the messages between them, and the solver that rank 0 runs on a thread
// of its own beside the coordinator (docs/produce.md, "On a cluster").
//
// Messages (core/cluster.hpp), one byte of kind first; solver -> coordinator all on one tag, so
// that each rank's messages arrive in the order it sent them (rank 0's own solver hands them
// over in memory, in order too):
//   hello  <rest signature>                 a rank is ready, with its rest state's identity
//   node   <checkpoint record>              a first-pass node finished (its state when converged)
//   ready  <busy s>                         a rank finished its task (busy: the task's wall time)
//   move   <job> <busy s> <record>          branch job solved (its state when it moved)
//   error  <text>                           a rank failed; rank 0 ends the run
// coordinator -> a solver:
//   task   <task> <done ids> <records>      solve this sector's nodes not listed done; the records
//                                           are the states its nodes start from (solved elsewhere
//                                           or resumed)
//   target <job> <node> <best> <records>    solve node from each record's state, accept below best
//   stop
#include <condition_variable>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "produce/produce_pass.hpp"

namespace yarnhom::yarn::cluster_produce {

inline constexpr int kToRoot = 1, kToWorker = 2;
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

// A branch job's result travels as a record: its state present when it moved.
CheckpointRecord move_record(const BranchMove& mv);
BranchMove move_of(CheckpointRecord&& rec);

// A branch job's result from its sources' solves apart (each a branch_solve from that source
// alone, below best), as branch_solve from all of them in that order gives it: a source wins
// when it moved and lies below every earlier winner.
BranchMove combine_sources(double best, const std::vector<BranchMove>& parts);

// The calling thread's CPU seconds.
double thread_cpu_seconds();

// Messages handed from one thread to another, in order.
class Mailbox {
 public:
  void push(std::string m);
  // The oldest message, waiting for one at most `wait_ms` (< 0: for ever); false if none came.
  bool pop(std::string& m, int wait_ms);

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::string> q_;
};

// Rank 0's own solver: a thread with its own copy of the run's nodes (the solves never touch the
// coordinator's), fed and answered through two mailboxes in the messages' own bytes, so that the
// coordinator treats it as one more rank (rank 0). Only the coordinator's thread calls MPI.
class LocalSolver {
 public:
  explicit LocalSolver(const ProduceRun& run);
  ~LocalSolver();  // sends stop if not sent, and joins
  Mailbox inbox, outbox;

 private:
  ProduceOptions opt_;  // the run's, without the progress lines (the coordinator prints those)
  std::unique_ptr<ProduceRun> run_;
  std::thread thread_;
};

}  // namespace yarnhom::yarn::cluster_produce
