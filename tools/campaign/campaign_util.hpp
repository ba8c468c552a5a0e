#pragma once
// What every part of the hardening campaign (harden_campaign.cpp, campaign_new_commands.cpp)
// shares: running the program under a time limit and reading its output, and the verdict on a
// command line that must be refused cleanly.
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace campaign {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

inline std::string g_bin;  // the yarnhom binary under test

inline double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The program in its own process group, stdout and stderr to log.
inline pid_t spawn(const std::vector<std::string>& args, const std::string& log) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

struct Run {
  int status;  // exit status; 128 + signal
  double seconds;
  std::string out;
  bool timed_out = false;  // killed by the limit
};

inline Run run(const std::vector<std::string>& args, double limit = 60) {
  const std::string log = (fs::temp_directory_path() / ("campaign_" + std::to_string(::getpid()) + ".log")).string();
  const auto t0 = Clock::now();
  const pid_t pid = spawn(args, log);
  int st = 0;
  bool killed = false;
  for (;;) {
    const pid_t r = ::waitpid(pid, &st, WNOHANG);
    if (r == pid) break;
    if (!killed && since(t0) > limit) ::kill(-pid, SIGKILL), killed = true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  Run r{WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st), since(t0), "", killed};
  std::ifstream in(log);
  r.out.assign(std::istreambuf_iterator<char>(in), {});
  fs::remove(log);
  return r;
}

inline std::vector<std::string> cmd(std::initializer_list<std::string> a) {
  std::vector<std::string> v = {g_bin};
  v.insert(v.end(), a.begin(), a.end());
  return v;
}

// A command line split at spaces ('' is an empty argument; a '...' group is one argument).
inline std::vector<std::string> split_cmd(const std::string& line) {
  std::vector<std::string> v = {g_bin};
  std::string cur;
  bool quoted = false, any = false;
  for (char c : line) {
    if (c == '\'') quoted = !quoted, any = true;
    else if (c == ' ' && !quoted) {
      if (any || !cur.empty()) v.push_back(cur);
      cur.clear(), any = false;
    } else cur += c;
  }
  if (any || !cur.empty()) v.push_back(cur);
  return v;
}

inline std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

inline int count_partials(const fs::path& dir) {
  int n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->path().filename().string().find(".partial") != std::string::npos) ++n;
  return n;
}

inline unsigned file_type(const std::string& p) {
  struct stat st;
  return ::lstat(p.c_str(), &st) == 0 ? (st.st_mode & S_IFMT) : 0;
}

inline std::string join_args(const std::vector<std::string>& a) {
  std::string line;
  for (size_t i = 1; i < a.size(); ++i) line += (i > 1 ? " " : "") + (a[i].empty() ? std::string("''") : a[i]);
  return line;
}

// Texts that only a library writes: never in a refusal.
inline const char* library_text(const std::string& out) {
  for (const char* lib : {"std::", "bad_alloc", "json.exception", "filesystem error", "basic_filebuf", "what():",
                          "terminate called", "HDF5-DIAG", "Assertion"})
    if (out.find(lib) != std::string::npos) return lib;
  return nullptr;
}

// The categories of the acceptance.
struct Tally {
  int cases = 0, crashes = 0, hangs = 0, unclean = 0, accepted = 0, clobbered = 0, slow = 0;
  double slowest_refusal = 0;
  void add(const Tally& t) {
    cases += t.cases, crashes += t.crashes, hangs += t.hangs, unclean += t.unclean, accepted += t.accepted;
    clobbered += t.clobbered, slow += t.slow;
    slowest_refusal = std::max(slowest_refusal, t.slowest_refusal);
  }
  void print(const char* what) const {
    std::printf("%s: %d cases: %d crashes, %d hangs, %d unclean messages, %d invalid values accepted, %d clobbered, "
                "%d refusals over 5 s (slowest refusal %.2f s)\n",
                what, cases, crashes, hangs, unclean, accepted, clobbered, slow, slowest_refusal);
  }
};

// The verdict on one run: must_refuse says the input is invalid; names are what the message must
// name (one of them) when it refuses. Prints one line (two with the message) and counts.
inline std::string judge(const std::vector<std::string>& args, const Run& r, bool must_refuse,
                         const std::vector<std::string>& names, Tally& t, bool nonfinite_output = false) {
  ++t.cases;
  bool named = names.empty();
  for (const auto& n : names) named = named || r.out.find(n) != std::string::npos;
  std::string verdict;
  if (r.timed_out) verdict = "HANG", ++t.hangs;
  else if (r.status >= 128) verdict = "CRASH: signal " + std::to_string(r.status - 128), ++t.crashes;
  else if (r.status == 0 && (must_refuse || nonfinite_output)) verdict = "ACCEPTED", ++t.accepted;
  else if (r.status == 0) verdict = "ran";
  else if (const char* lib = library_text(r.out)) verdict = std::string("UNCLEAN: library text ") + lib, ++t.unclean;
  else if (!named) verdict = "UNCLEAN: names neither the file nor the option", ++t.unclean;
  else verdict = "refused";
  if (r.status != 0 && !r.timed_out) {
    t.slowest_refusal = std::max(t.slowest_refusal, r.seconds);
    if (r.seconds > 5) ++t.slow, verdict += " (SLOW)";
  }
  // The message: the error line where there is one, else the last line.
  std::string msg;
  const size_t err = r.out.find("error");
  if (err != std::string::npos) {
    const size_t b = r.out.rfind('\n', err);
    msg = r.out.substr(b == std::string::npos ? 0 : b + 1);
  } else {
    std::string t = r.out;
    while (!t.empty() && t.back() == '\n') t.pop_back();
    msg = t.substr(t.rfind('\n') == std::string::npos ? 0 : t.rfind('\n') + 1);
  }
  msg = msg.substr(0, msg.find('\n'));
  if (verdict == "ran") msg.clear();
  if (msg.size() > 160) msg = msg.substr(0, 160) + "...";
  std::printf("   %6.2f s  %-9s %s\n", r.seconds, verdict.substr(0, verdict.find(':')).c_str(), join_args(args).c_str());
  if (!msg.empty()) std::printf("            %s\n", msg.c_str());
  std::fflush(stdout);
  return verdict;
}

}  // namespace campaign
