#include "pipeline/stage_runner.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <thread>

#include "core/console.hpp"
#include "core/text_file.hpp"
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

namespace {

std::string g_run_id;
std::function<void()> g_wait_hook;

std::string read_small_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string s;
  std::getline(in, s, '\0');
  return s;
}

// DIR/.stages/<name>.lock held for the lifetime of the object (released by close, or by the
// kernel when the process dies). Waits for another holder, saying who it is, and writes its own
// name into the file for the next one.
class StageLock {
 public:
  StageLock(const fs::path& path, const std::string& name, int width) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw std::runtime_error("cannot open the stage lock " + path.string() + ": " + std::strerror(errno));
    bool said = false;
    while (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      if (errno == ENOSYS || errno == EOPNOTSUPP || errno == ENOLCK) {
        // A file system without locks (Lustre mounted without -o flock): one process runs as
        // before; ranks of one mpirun still run each stage once unless two reach it together.
        static bool told = false;
        if (!told)
          std::fprintf(stderr, "yarnhom: note: %s: this file system has no flock (%s); stages are not locked\n",
                       path.string().c_str(), std::strerror(errno));
        told = true;
        return;
      }
      if (errno != EWOULDBLOCK && errno != EINTR)
        throw std::runtime_error("cannot lock " + path.string() + ": " + std::strerror(errno));
      if (!said) {
        std::printf("  %-*s waiting for %s, which runs it ...\n", width, name.c_str(), holder(path).c_str());
        std::fflush(stdout);
        said = true;
      }
      if (g_wait_hook) g_wait_hook();
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
    char host[256] = {0};
    ::gethostname(host, sizeof host - 1);
    const std::string me = "process " + std::to_string(::getpid()) + " on " + host;
    if (::ftruncate(fd_, 0) == 0) {
      [[maybe_unused]] const ssize_t w = ::pwrite(fd_, me.data(), me.size(), 0);  // for the message of one that waits
    }
  }
  ~StageLock() { ::close(fd_); }
  StageLock(const StageLock&) = delete;
  StageLock& operator=(const StageLock&) = delete;

 private:
  static std::string holder(const fs::path& path) {
    const std::string h = read_small_file(path.string());
    return h.empty() ? "another process" : h;
  }
  int fd_ = -1;
};

// The child's latest progress line in its log (the last piece, between '\r' or '\n', that
// says "ETA" or "elapsed"), "" when there is none yet.
std::string latest_progress(const std::string& log) {
  std::ifstream in(log, std::ios::binary | std::ios::ate);
  if (!in) return "";
  const std::streamoff size = in.tellg(), n = std::min<std::streamoff>(size, 4096);
  std::string tail(size_t(n), '\0');
  in.seekg(size - n);
  in.read(tail.data(), n);
  size_t end = tail.size();
  while (end > 0) {
    const size_t b = tail.find_last_of("\r\n", end - 1);
    const size_t from = b == std::string::npos ? 0 : b + 1;
    std::string piece = tail.substr(from, end - from);
    while (!piece.empty() && piece.back() == ' ') piece.pop_back();
    if (piece.find("ETA") != std::string::npos || piece.find("elapsed") != std::string::npos) return piece;
    if (b == std::string::npos) break;
    end = b;
  }
  return "";
}

// The terminal's width (columns), 120 when it does not say.
int terminal_columns() {
  winsize w{};
  return ::ioctl(STDOUT_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col > 20 ? w.ws_col : 120;
}

}  // namespace

std::string stage_run_id() {
  if (g_run_id.empty()) {
    char host[256] = {0};
    ::gethostname(host, sizeof host - 1);
    g_run_id = std::string(host) + ":" + std::to_string(::getpid()) + ":" +
               std::to_string(std::chrono::system_clock::now().time_since_epoch().count());
  }
  return g_run_id;
}

void set_stage_run_id(const std::string& id) { g_run_id = id; }

void set_stage_wait_hook(std::function<void()> hook) { g_wait_hook = std::move(hook); }

StageOutcome run_stage_child(const fs::path& dir, const StageSpec& s, bool force, int width) {
  fs::create_directories(dir / "logs");
  fs::create_directories(dir / ".stages");
  const StageLock lock(dir / ".stages" / (s.name + ".lock"), s.name, width);
  std::string settings;
  for (const std::string& a : s.args) settings += a + "\n";
  const std::string stamp = (dir / ".stages" / (s.name + ".done")).string();
  const std::string forced = (dir / ".stages" / (s.name + ".forced")).string();
  StageDecision d = stage_decision(s.inputs, s.outputs, stamp, settings);
  if (force && (d.run || read_small_file(forced) != stage_run_id())) d = {true, "--force"};
  StageOutcome out;
  out.log = (dir / "logs" / (s.name + ".log")).string();
  if (!d.run) {
    std::printf("  %-*s skipped (up to date%s)\n", width, s.name.c_str(), force ? ", forced earlier in this run" : "");
    return out;
  }
  char head[400];
  std::snprintf(head, sizeof head, "  %-*s running (%s) ...", width, s.name.c_str(), d.reason.c_str());
  std::printf("%s", head);
  std::fflush(stdout);
  std::vector<std::string> argv = {self_executable()};
  argv.insert(argv.end(), s.args.begin(), s.args.end());
  const auto t0 = std::chrono::steady_clock::now();
  // On a terminal the line shows the stage's own progress line (its log's latest, with its ETA),
  // redrawn in place; in a file or a pipe the output stays as it was.
  const bool tty = ::isatty(STDOUT_FILENO) == 1;
  bool shown = false;
  std::function<void()> relay, tick;
  char short_head[80];
  std::snprintf(short_head, sizeof short_head, "  %-*s ", width, s.name.c_str());
  if (tty) {
    ::setenv("YARNHOM_PROGRESS_SECONDS", "1", 0);  // the children's progress lines once a second
    relay = [&] {
      std::string p = latest_progress(out.log);
      if (p.empty()) return;
      if (p.rfind(s.args[0] + " ", 0) == 0) p = p.substr(s.args[0].size() + 1);  // "produce NAME: ..." once
      const size_t room = size_t(std::max(20, terminal_columns() - 1 - int(std::strlen(short_head))));
      if (p.size() > room) p = p.substr(0, room - 3) + "...";
      std::printf("\r%s%s\x1b[K", short_head, p.c_str());
      std::fflush(stdout);
      shown = true;
    };
  }
  if (relay || g_wait_hook)
    tick = [&] {
      if (relay) relay();
      if (g_wait_hook) g_wait_hook();
    };
  out.status = run_child(argv, s.stdout_file.empty() ? out.log : s.stdout_file, out.log, tick);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.ran = true;
  if (shown) std::printf("\r%s\x1b[K", head);  // the caller or the line below ends it
  if (out.status != 0) return out;
  write_stage_stamp(stamp, settings);
  if (force) write_text_file(forced, stage_run_id(), "cannot write the stage record");
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
