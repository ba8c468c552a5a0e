#pragma once
// Cached, resumable stages for the commands that chain other subcommands (accuracy, study),
// with the same mechanism as `pipeline` (bake/pipeline_stage.hpp): a stage runs this same
// program with a subcommand in a child process, its output in DIR/logs/<name>.log, and is
// skipped when its outputs exist, no input is newer than them and its record
// DIR/.stages/<name>.done holds the same settings. The record is written after success only, so
// an interrupted run continues where it stopped. A stage dies with its parent
// (tools/child_process.hpp): killing accuracy or study never leaves a stage running.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "bake/pipeline_stage.hpp"
#include "tools/child_process.hpp"
#include "tools/cli_util.hpp"

namespace yarnhom::tools {

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
};

inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string self_executable() { return std::filesystem::read_symlink("/proc/self/exe").string(); }

// Runs (or skips) one stage in `dir`; prints one progress line; throws std::runtime_error naming
// the log when the stage fails.
inline StageOutcome run_stage(const std::filesystem::path& dir, const StageSpec& s, bool force) {
  namespace fs = std::filesystem;
  fs::create_directories(dir / "logs");
  fs::create_directories(dir / ".stages");
  std::string settings;
  for (const std::string& a : s.args) settings += a + "\n";
  const std::string stamp = (dir / ".stages" / (s.name + ".done")).string();
  StageDecision d = stage_decision(s.inputs, s.outputs, stamp, settings);
  if (force) d = {true, "--force"};
  StageOutcome out;
  out.log = (dir / "logs" / (s.name + ".log")).string();
  if (!d.run) {
    std::printf("  %-14s skipped (up to date)\n", s.name.c_str());
    return out;
  }
  std::printf("  %-14s running (%s) ...", s.name.c_str(), d.reason.c_str());
  std::fflush(stdout);
  std::vector<std::string> argv = {self_executable()};
  argv.insert(argv.end(), s.args.begin(), s.args.end());
  const auto t0 = std::chrono::steady_clock::now();
  const int rc = run_child(argv, s.stdout_file.empty() ? out.log : s.stdout_file, out.log);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.ran = true;
  if (rc != 0) {
    std::printf(" failed after %s\n", format_seconds(out.seconds).c_str());
    if (!s.stdout_file.empty()) fs::remove(s.stdout_file);
    throw std::runtime_error("stage " + s.name + " failed (exit status " + std::to_string(rc) + "); see " + out.log);
  }
  write_stage_stamp(stamp, settings);
  std::printf(" done in %s\n", format_seconds(out.seconds).c_str());
  return out;
}

}  // namespace yarnhom::tools
