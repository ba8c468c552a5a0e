#include "core/file_checks.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace yarnhom {

namespace fs = std::filesystem;

std::string file_kind(unsigned mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISREG(mode)) return "a regular file";
  return "not a regular file";
}

namespace {

std::string with(const std::string& what, const std::string& problem) {
  return what.empty() ? problem : problem + " (" + what + ")";
}

std::string parent_of(const std::string& path) {
  const fs::path p = fs::path(path).parent_path();
  return p.empty() ? "." : p.string();
}

}  // namespace

void check_input_file(const std::string& path, const std::string& what) {
  struct stat st;
  if (path.empty()) throw FileError("''", "", with(what, "empty file name"));
  if (::stat(path.c_str(), &st) != 0)
    throw FileError(path, "", with(what, errno == ENOENT ? "no such file" : std::strerror(errno)));
  if (!S_ISREG(st.st_mode))
    throw FileError(path, "", with(what, "is " + file_kind(st.st_mode) + ", not a regular file"));
}

std::string check_output_file(const std::string& path, const std::vector<std::string>& inputs,
                              const std::string& option) {
  auto fail = [&](const std::string& problem) -> void { throw FileError(path, "", problem + " (" + option + ")"); };
  if (path.empty()) throw FileError("''", "", "empty output file name (" + option + ")");
  if (path.back() == '/') fail("names a folder; give a file name");
  std::string target = path;
  struct stat lst, st;
  const bool exists = ::lstat(path.c_str(), &lst) == 0;
  if (exists && S_ISLNK(lst.st_mode)) {
    if (::stat(path.c_str(), &st) != 0)
      fail("is a symbolic link to a missing file; outputs follow links only to existing regular files");
    char buf[PATH_MAX];
    if (!::realpath(path.c_str(), buf)) fail(std::string("cannot resolve the symbolic link: ") + std::strerror(errno));
    target = buf;
  } else if (exists) {
    st = lst;
  }
  if (exists) {
    if (S_ISDIR(st.st_mode)) fail("is a directory; give a file name");
    if (!S_ISREG(st.st_mode))
      fail("is " + file_kind(st.st_mode) + ", not a regular file: refusing to replace it");
    for (const std::string& in : inputs) {
      struct stat ist;
      if (in.empty() || ::stat(in.c_str(), &ist) != 0) continue;
      if (ist.st_dev == st.st_dev && ist.st_ino == st.st_ino)
        fail(in == path ? "is also an input of this command: writing it would destroy it"
                        : "is the same file as the input " + in + ": writing it would destroy it");
    }
  }
  const std::string dir = parent_of(target);
  struct stat dst;
  if (::stat(dir.c_str(), &dst) != 0) fail("its folder " + dir + " does not exist");
  if (!S_ISDIR(dst.st_mode)) fail(dir + " is not a folder");
  // The only sure test of "can a file be created here" is creating one: the name is the one
  // AtomicOutput uses for the temporary, removed at once.
  const std::string probe = AtomicOutput::temporary_name(target, ::getpid());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0 && errno != EEXIST) fail("cannot create a file in " + dir + ": " + std::strerror(errno));
  if (fd >= 0) {
    ::close(fd);
    ::unlink(probe.c_str());
  }
  return target;
}

void check_output_folder(const std::string& path, const std::string& option) {
  auto fail = [&](const std::string& problem) -> void { throw FileError(path, "", problem + " (" + option + ")"); };
  if (path.empty()) throw FileError("''", "", "empty folder name (" + option + ")");
  // access() says yes to root almost everywhere (/proc, /sys): the only sure test of "can
  // something be made here" is making it, a probe named after this process, removed at once.
  const std::string probe_name = ".yarnhom-probe-" + std::to_string(::getpid());
  struct stat st;
  if (::stat(path.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode)) fail("is " + file_kind(st.st_mode) + ", not a folder");
    if (::access(path.c_str(), W_OK | X_OK) != 0) fail(std::string("cannot write in this folder: ") + std::strerror(errno));
    const std::string probe = (fs::path(path) / probe_name).string();
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0 && errno != EEXIST) fail(std::string("cannot create a file in this folder: ") + std::strerror(errno));
    if (fd >= 0) {
      ::close(fd);
      ::unlink(probe.c_str());
    }
    return;
  }
  if (errno != ENOENT && errno != ENOTDIR) fail(std::string("cannot reach it: ") + std::strerror(errno));
  // Missing: it (and missing parents) will be created below the nearest existing ancestor.
  fs::path p = fs::absolute(path).lexically_normal();
  while (p.has_parent_path() && p != p.parent_path()) {
    p = p.parent_path();
    if (::stat(p.c_str(), &st) != 0) {
      if (errno != ENOENT && errno != ENOTDIR) fail("cannot reach " + p.string() + ": " + std::strerror(errno));
      continue;
    }
    if (!S_ISDIR(st.st_mode)) fail(p.string() + " is " + file_kind(st.st_mode) + ", not a folder");
    if (::access(p.c_str(), W_OK | X_OK) != 0) fail("cannot create it in " + p.string() + ": " + std::strerror(errno));
    const std::string probe = (p / probe_name).string();
    if (::mkdir(probe.c_str(), 0755) != 0 && errno != EEXIST)
      fail("cannot create it in " + p.string() + ": " + std::strerror(errno));
    ::rmdir(probe.c_str());
    return;
  }
  fail("cannot find an existing folder to create it in");
}

}  // namespace yarnhom
