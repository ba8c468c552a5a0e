#pragma once
// Runs the yarnhom program (YARNHOM_BINARY) with arguments and returns its exit status and its
// stdout and stderr together.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace yarnhom::test {

// The program, found from this test executable's folder (YARNHOM_BINARY_FROM_TESTS, the
// relative path tests/CMakeLists.txt defines for the tools tests: ../tools/yarnhom), so that no
// test file's command names the build folder and ccache gives the CUDA-off build the CUDA-on
// build's objects (docs/layout.md, "CI").
inline const char* yarnhom_binary() {
  static const std::string path = (std::filesystem::read_symlink("/proc/self/exe").parent_path() /
                                   YARNHOM_BINARY_FROM_TESTS).lexically_normal().string();
  return path.c_str();
}
#define YARNHOM_BINARY (::yarnhom::test::yarnhom_binary())

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
