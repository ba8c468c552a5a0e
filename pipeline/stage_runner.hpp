#pragma once
// Cached, resumable stages for the commands that chain other subcommands (pipeline, accuracy,
// study), on the mechanism of pipeline/pipeline_stage.hpp: a stage runs this same program with a
// subcommand in a child process, its output in DIR/logs/<name>.log, and is skipped when its
// outputs exist, no input is newer than them and its record DIR/.stages/<name>.done holds the
// same settings. The record is written after success only, so an interrupted run continues where
// it stopped. A stage dies with its parent (pipeline/child_process.hpp): killing pipeline,
// accuracy or study never leaves a stage running.
//
// A stage is claimed with an exclusive lock on DIR/.stages/<name>.lock (flock; it works on the
// shared file systems of clusters, and the kernel releases it when its holder dies): a process
// that wants a stage another one is running (another rank of `mpirun ... study`, or a second
// command over the same folder) waits for it and then finds it done. --force runs a stage once
// per run: a stage forced earlier in the same run (the same run id, which the ranks of one
// mpirun share) is not run again.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace yarnhom::pipeline {

struct StageSpec {
  std::string name;               // also the log and record name
  std::vector<std::string> args;  // subcommand and its arguments
  std::vector<std::string> inputs, outputs;
  std::string stdout_file = {};   // when set, the command's stdout goes there (stderr to the log)
};

struct StageOutcome {
  bool ran = false;
  double seconds = 0;
  std::string log;
  int status = 0;  // the child's exit status (0 when skipped)
};

std::string shell_quote(const std::string& s);
std::string self_executable();

// Appends "FLAG VALUE" when value > 0 (threads, epochs: 0 means the subcommand's default).
void add_count_option(std::vector<std::string>& args, const char* flag, int value);

// This run's id (host, process and time, made on first use), and setting it (the ranks of one
// mpirun take rank 0's).
std::string stage_run_id();
void set_stage_run_id(const std::string& id);

// Called about 4 times a second while this process waits for a stage (its child, or another
// process's lock): rank 0 of a study hands out work meanwhile (pipeline/rank_tasks.hpp).
void set_stage_wait_hook(std::function<void()> hook);

// Runs (or skips) one stage in `dir`, its name padded to `width` in the progress line
// ("  NAME skipped (up to date)" or "  NAME running (why) ..."). On success records it and ends
// the line with " done in T"; on failure returns the status and leaves the line to the caller.
StageOutcome run_stage_child(const std::filesystem::path& dir, const StageSpec& s, bool force, int width);

// run_stage_child for accuracy and the studies: throws std::runtime_error naming the log when
// the stage fails (its stdout file removed).
StageOutcome run_stage(const std::filesystem::path& dir, const StageSpec& s, bool force);

}  // namespace yarnhom::pipeline
