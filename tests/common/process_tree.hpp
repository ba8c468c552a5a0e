#pragma once
// A process's children and descendants, and whether it still runs (Linux /proc): what the kill
// tests (tests/tools) and the hardening campaign (tools/campaign) check after killing a run.
#include <sys/types.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

namespace yarnhom::test {

// Direct children of pid (every thread's list).
inline std::vector<pid_t> children_of(pid_t pid) {
  std::vector<pid_t> out;
  std::error_code ec;
  for (auto& t : std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task", ec)) {
    std::ifstream in(t.path() / "children");
    for (pid_t c; in >> c;) out.push_back(c);
  }
  return out;
}

// Every descendant of pid, depth first.
inline std::vector<pid_t> descendants(pid_t pid) {
  std::vector<pid_t> out, frontier = {pid};
  while (!frontier.empty()) {
    const pid_t p = frontier.back();
    frontier.pop_back();
    for (pid_t c : children_of(p)) {
      out.push_back(c);
      frontier.push_back(c);
    }
  }
  return out;
}

// Running (not a zombie, not gone).
inline bool alive(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(in, line)) return false;
  const auto close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

}  // namespace yarnhom::test
