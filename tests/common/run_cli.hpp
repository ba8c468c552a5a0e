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

inline CliResult run_cli(const std::string& args) {
  const std::string cmd = std::string(YARNHOM_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

}  // namespace yarnhom::test
