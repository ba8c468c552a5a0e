#pragma once
// Child processes that die with their parent. `pipeline` runs its stages, and `plot` its
// python script, as children; with std::system (a shell, then the program) a killed pipeline
// left its stages running for seconds or minutes, racing a rerun over the same files. Here the
// child asks the kernel for SIGKILL when its parent dies (Linux prctl PR_SET_PDEATHSIG), by
// any cause, SIGKILL included, and there is no shell in between.
#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

namespace yarnhom::pipeline {

// Runs argv (argv[0] looked up in PATH when it has no '/') and waits for it. Its stdout goes
// to out_path and its stderr to err_path ("" keeps this process's; the same path twice shares
// one file). Returns the exit status, 128 + the signal when a signal ended it, 127 when it
// could not be started. `tick`, when given, is called about 4 times a second while the child
// runs (a stage runner relays the child's progress line with it).
inline int run_child(const std::vector<std::string>& argv, const std::string& out_path = "",
                     const std::string& err_path = "", const std::function<void()>& tick = {}) {
  // Everything the child needs is prepared before fork: after it only async-signal-safe calls.
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) return 127;
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);  // the parent died before prctl took effect
    if (!out_path.empty()) {
      const int fd = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd < 0) ::_exit(127);
      ::dup2(fd, 1);
      if (err_path == out_path) ::dup2(fd, 2);
      ::close(fd);
    }
    if (!err_path.empty() && err_path != out_path) {
      const int fd = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd < 0) ::_exit(127);
      ::dup2(fd, 2);
      ::close(fd);
    }
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  int st = 0;
  if (tick) {
    for (int k = 0;; ++k) {
      const pid_t r = ::waitpid(pid, &st, WNOHANG);
      if (r == pid) break;
      if (r < 0 && errno != EINTR) return 127;
      if (k % 5 == 4) tick();
      const timespec pause{0, 50'000'000};
      ::nanosleep(&pause, nullptr);
    }
  } else {
    while (::waitpid(pid, &st, 0) < 0)
      if (errno != EINTR) return 127;
  }
  if (WIFEXITED(st)) return WEXITSTATUS(st);
  if (WIFSIGNALED(st)) return 128 + WTERMSIG(st);
  return 127;
}

}  // namespace yarnhom::pipeline
