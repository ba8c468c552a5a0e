#include "core/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "core/error.hpp"

namespace yarnhom {

AtomicOutput::AtomicOutput(std::string final_path)
    : final_(std::move(final_path)),
      temp_(final_ + ".partial-" + std::to_string(static_cast<long>(::getpid()))) {}

AtomicOutput::~AtomicOutput() {
  if (!committed_) std::remove(temp_.c_str());
}

void AtomicOutput::commit() {
  if (std::rename(temp_.c_str(), final_.c_str()) != 0)
    throw FileError(final_, "", std::string("cannot move the finished file into place: ") +
                                    std::strerror(errno));
  committed_ = true;
}

}  // namespace yarnhom
