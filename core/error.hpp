#pragma once
// Errors that name what was wrong and where: the file, the object inside it, the problem.
#include <stdexcept>
#include <string>

namespace yarnhom {

class FileError : public std::runtime_error {
 public:
  FileError(const std::string& file, const std::string& object, const std::string& problem)
      : std::runtime_error(file + (object.empty() ? "" : ": " + object) + ": " + problem),
        file_(file), object_(object), problem_(problem) {}
  const std::string& file() const { return file_; }
  const std::string& object() const { return object_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_, object_, problem_;
};

}  // namespace yarnhom
