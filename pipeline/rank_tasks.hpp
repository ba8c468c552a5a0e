#pragma once
// `accuracy` and the accuracy studies on the ranks of an mpirun (docs/produce.md, "The studies
// on a cluster"). Every rank builds the same tasks from the same options: pieces of the study
// (a yarn strip, a dataset, a network's training and baking, a continuum strip), each a few
// cached stages (pipeline/stage_runner.hpp), with the tasks each needs done first. Rank 0 hands
// them out as they become ready, the longest chain of work first, to whichever rank asks (a rank
// that finishes early takes the next; rank 0 runs tasks too and hands out work while its own
// stage runs). A stage that two tasks share runs once: its lock makes the second wait and then
// find it done. When every task is done, rank 0 runs the study once more as one process would:
// every stage is found done, and it measures and writes the same tables and files.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace yarnhom::pipeline {

struct RankTask {
  std::string key;         // what makes two tasks the same (a stage record's path)
  std::string label;       // for the progress lines
  double weight = 1;       // guessed cost, any unit (orders the work and the ETA)
  std::vector<int> after;  // tasks done before this one (indices)
  std::function<void()> run;
};

class RankTasks {
 public:
  // Adds a task, or finds the one with this key (the first one's run stands); its index.
  // Entries of `after` below 0 stand for nothing.
  int add(const std::string& key, const std::string& label, double weight, const std::vector<int>& after,
          std::function<void()> run);
  const std::vector<RankTask>& tasks() const { return tasks_; }

 private:
  std::vector<RankTask> tasks_;
};

// The threads a rank's stages take by default: this rank's CPUs, at most the node's CPUs shared
// among the ranks on the node (at least 1).
int threads_per_rank();

// The task phase of a command on several ranks. One process: does nothing (root() true).
// Several: every rank constructs it with the same tasks (built by `build`); each rank's output
// goes to DIR/logs/rank-R.log meanwhile, and rank 0 prints the progress (every rank's tasks, the
// ETA at the pace so far). On rank 0 the constructor returns when every task is done, root() is
// true and the command's single pass follows; the other ranks return when rank 0's object is
// destroyed (root() false: they are done). Sets OMP_NUM_THREADS to threads_per_rank() unless it
// is set, so that every stage's default thread count is the rank's share. A task's exception
// ends the run (main: cluster::abort names the rank).
class OnRanks {
 public:
  OnRanks(const std::filesystem::path& dir, const std::string& what, const std::function<void(RankTasks&)>& build);
  ~OnRanks();
  OnRanks(const OnRanks&) = delete;
  OnRanks& operator=(const OnRanks&) = delete;
  bool root() const { return root_; }

 private:
  bool root_ = true, several_ = false;
};

}  // namespace yarnhom::pipeline
