#pragma once
// Write-then-rename: an output is written under a temporary name beside its final path and
// renamed over it only when complete, so an interrupted or failed run never leaves a
// half-written file and never destroys an existing one (rename is atomic on POSIX).
#include <string>

namespace yarnhom {

class AtomicOutput {
 public:
  explicit AtomicOutput(std::string final_path);
  ~AtomicOutput();  // removes the temporary file unless commit() succeeded
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  const std::string& temp_path() const { return temp_; }
  const std::string& final_path() const { return final_; }
  void commit();  // rename temp -> final; throws FileError on failure

 private:
  std::string final_, temp_;
  bool committed_ = false;
};

}  // namespace yarnhom
