#pragma once
// The fuzz tests' runner (tests/tools/test_fuzz_*.cpp): every mutant of one input kind is read
// and used in a forked child with an alarm per mutant, so that a crash or a hang is reported
// with the kind, the mutant's number and its file (kept for reproduction) instead of taking the
// test runner down. A refusal must be an exception whose message names the file and holds no
// library text ("std::", "json.exception").
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace yarnhom::test {

namespace fs = std::filesystem;

struct Kind {
  std::string name;
  std::function<void(const std::string&)> use;
  std::vector<std::string> mutants;  // file paths
};

// Runs every mutant of a kind in a child; returns the failures (empty: all good) and counts the
// mutants refused (the others were read and used).
inline std::vector<std::string> run_kind(const Kind& k, const fs::path& keep, int* refused) {
  int fds[2];
  if (::pipe(fds) != 0) return {"pipe failed"};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    FILE* out = ::fdopen(fds[1], "w");
    for (size_t i = 0; i < k.mutants.size(); ++i) {
      const std::string& file = k.mutants[i];
      std::fprintf(out, "start %zu\n", i);
      std::fflush(out);
      ::alarm(10);  // a hang ends the child with SIGALRM: reported below
      std::string bad;
      try {
        k.use(file);
      } catch (const std::exception& e) {
        const std::string msg = e.what();
        std::fprintf(out, "refused %zu\n", i);
        if (msg.find(file) == std::string::npos || msg.find("std::") != std::string::npos ||
            msg.find("json.exception") != std::string::npos)
          bad = "message does not name the file: " + msg;
      } catch (...) {
        bad = "non-standard exception";
      }
      ::alarm(0);
      if (!bad.empty()) {
        for (char& c : bad)
          if (c == '\n') c = ' ';
        std::fprintf(out, "bad %zu %s\n", i, bad.c_str());
      }
    }
    std::fprintf(out, "done\n");
    std::fclose(out);
    ::_exit(0);
  }
  ::close(fds[1]);
  FILE* in = ::fdopen(fds[0], "r");
  std::vector<std::string> failures;
  long last = -1;
  bool done = false;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, in)) {
    std::string line(buf);
    if (line.rfind("start ", 0) == 0) last = std::stol(line.substr(6));
    else if (line.rfind("refused ", 0) == 0) ++*refused;
    else if (line.rfind("bad ", 0) == 0) {
      const long i = std::stol(line.substr(4));
      fs::copy_file(k.mutants[i], keep / fs::path(k.mutants[i]).filename(), fs::copy_options::overwrite_existing);
      failures.push_back(k.name + " mutant " + std::to_string(i) + " (kept as " +
                         (keep / fs::path(k.mutants[i]).filename()).string() + "): " + line.substr(line.find(' ', 4) + 1));
    } else if (line == "done\n") done = true;
  }
  std::fclose(in);
  int st = 0;
  ::waitpid(pid, &st, 0);
  if (!done && last >= 0) {
    fs::copy_file(k.mutants[last], keep / fs::path(k.mutants[last]).filename(), fs::copy_options::overwrite_existing);
    failures.push_back(k.name + " mutant " + std::to_string(last) + " (kept as " +
                       (keep / fs::path(k.mutants[last]).filename()).string() + ") " +
                       (WIFSIGNALED(st) ? (WTERMSIG(st) == SIGALRM ? "hung (over 10 s)" : "crashed with signal " + std::to_string(WTERMSIG(st)))
                                        : "ended the reader"));
  }
  return failures;
}

}  // namespace yarnhom::test
