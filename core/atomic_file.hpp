#pragma once
// Write-then-rename: an output is written under a temporary name beside its final path and
// renamed over it only when complete, so an interrupted or failed run never leaves a
// half-written file and never destroys an existing one (rename is atomic on POSIX).
//
// A final path that is a symbolic link to a regular file is followed: the temporary goes
// beside the link's target and replaces the target, the link stays (core/file_checks.hpp).
// A run killed during its final write (SIGKILL runs no destructor) leaves its temporary
// behind: remove_stale_temporaries() removes those of dead processes when the same output is
// written again.
#include <string>
#include <sys/types.h>
#include <vector>

namespace yarnhom {

class AtomicOutput {
 public:
  explicit AtomicOutput(std::string final_path);
  ~AtomicOutput();  // removes the temporary file unless commit() succeeded
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  const std::string& temp_path() const { return temp_; }
  const std::string& final_path() const { return final_; }
  // rename temp -> final; throws FileError on failure, and (without renaming) when the final
  // path has meanwhile become something other than a regular file (a device, a FIFO, ...).
  void commit();

  // "<final>.partial-<pid>": the temporary of process pid.
  static std::string temporary_name(const std::string& final_path, long pid);
  // Removes the temporaries of `final_path` left by processes that no longer run (and any of
  // this process, which has not started writing yet); returns the paths removed.
  static std::vector<std::string> remove_stale_temporaries(const std::string& final_path);

 private:
  std::string final_, temp_;
  bool committed_ = false;
};

}  // namespace yarnhom
