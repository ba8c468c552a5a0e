#include "pipeline/stage_runner.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "core/console.hpp"
#include "pipeline/child_process.hpp"
#include "pipeline/pipeline_stage.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string self_executable() { return fs::read_symlink("/proc/self/exe").string(); }

void add_count_option(std::vector<std::string>& args, const char* flag, int value) {
  if (value <= 0) return;
  args.push_back(flag);
  args.push_back(std::to_string(value));
}

StageOutcome run_stage_child(const fs::path& dir, const StageSpec& s, bool force, int width) {
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
    std::printf("  %-*s skipped (up to date)\n", width, s.name.c_str());
    return out;
  }
  std::printf("  %-*s running (%s) ...", width, s.name.c_str(), d.reason.c_str());
  std::fflush(stdout);
  std::vector<std::string> argv = {self_executable()};
  argv.insert(argv.end(), s.args.begin(), s.args.end());
  const auto t0 = std::chrono::steady_clock::now();
  out.status = run_child(argv, s.stdout_file.empty() ? out.log : s.stdout_file, out.log);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.ran = true;
  if (out.status != 0) return out;
  write_stage_stamp(stamp, settings);
  std::printf(" done in %s\n", format_seconds(out.seconds).c_str());
  return out;
}

StageOutcome run_stage(const fs::path& dir, const StageSpec& s, bool force) {
  const StageOutcome out = run_stage_child(dir, s, force, 14);
  if (out.status == 0) return out;
  std::printf(" failed after %s\n", format_seconds(out.seconds).c_str());
  if (!s.stdout_file.empty()) fs::remove(s.stdout_file);
  throw std::runtime_error("stage " + s.name + " failed (exit status " + std::to_string(out.status) + "); see " + out.log);
}

}  // namespace yarnhom::pipeline
