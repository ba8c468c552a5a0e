#pragma once
// Runs the yarnhom program (YARNHOM_BINARY, defined for the tools tests) with arguments and
// returns its exit status and its stdout and stderr together.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace yarnhom::test {

struct CliResult {
  int status;
  std::string out;
};

// Runs a shell command line; stdout and stderr together.
inline CliResult run_shell(const std::string& cmdline) {
  const std::string cmd = "{ " + cmdline + " ; } 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

inline CliResult run_cli(const std::string& args) { return run_shell(std::string(YARNHOM_BINARY) + " " + args); }

// The program under a wall-clock limit: a hang ends with status 137 (SIGKILL from timeout).
inline CliResult run_cli_limited(const std::string& args, int seconds = 30) {
  return run_shell("timeout -s KILL " + std::to_string(seconds) + " " + std::string(YARNHOM_BINARY) + " " + args);
}

}  // namespace yarnhom::test
