#include "core/atomic_file.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "core/error.hpp"
#include "core/file_checks.hpp"

namespace yarnhom {

namespace {

// The file a write to `path` lands in: the target of a symbolic link, else path itself.
std::string resolve(const std::string& path) {
  struct stat st;
  if (::lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return path;
  char buf[PATH_MAX];
  if (!::realpath(path.c_str(), buf))
    throw FileError(path, "", "is a symbolic link to a missing file; outputs follow links only to existing files");
  return buf;
}

}  // namespace

std::string AtomicOutput::temporary_name(const std::string& final_path, long pid) {
  return final_path + ".partial-" + std::to_string(pid);
}

AtomicOutput::AtomicOutput(std::string final_path)
    : final_(resolve(final_path)), temp_(temporary_name(final_, static_cast<long>(::getpid()))) {}

AtomicOutput::~AtomicOutput() {
  if (!committed_) std::remove(temp_.c_str());
}

void AtomicOutput::commit() {
  struct stat st;
  if (::stat(final_.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw FileError(final_, "", "is " + file_kind(st.st_mode) + ", not a regular file: refusing to replace it");
  if (std::rename(temp_.c_str(), final_.c_str()) != 0)
    throw FileError(final_, "", std::string("cannot move the finished file into place: ") +
                                    std::strerror(errno));
  committed_ = true;
}

std::vector<std::string> AtomicOutput::remove_stale_temporaries(const std::string& final_path) {
  namespace fs = std::filesystem;
  std::vector<std::string> removed;
  std::string target;
  try {
    target = resolve(final_path);
  } catch (const FileError&) {
    return removed;
  }
  const fs::path dir = fs::path(target).parent_path().empty() ? fs::path(".") : fs::path(target).parent_path();
  const std::string prefix = fs::path(target).filename().string() + ".partial-";
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) continue;
    const long pid = std::strtol(digits.c_str(), nullptr, 10);
    // kill(pid, 0) fails with ESRCH only when no such process exists: a live writer's
    // temporary (another run writing the same output right now) is left alone.
    const bool dead = pid != ::getpid() && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
    if (!dead && pid != ::getpid()) continue;
    struct stat st;
    if (::lstat(e.path().c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    if (::unlink(e.path().c_str()) == 0) removed.push_back(e.path().string());
  }
  return removed;
}

}  // namespace yarnhom
