#include "yarn/rod/load_pattern.hpp"

#include <filesystem>
#include <stdexcept>

#include "core/file_checks.hpp"
#include "yarn/rod/generate.hpp"

namespace yarnhom::yarn {

Pattern load_pattern(const std::string& name_or_path) {
  if (std::filesystem::exists(name_or_path)) {
    check_input_file(name_or_path, "PATTERN");
    return read_pyp(name_or_path);
  }
  if (is_builtin_pattern(name_or_path)) return builtin_pattern(name_or_path);
  throw std::invalid_argument("pattern '" + name_or_path + "' is neither a file nor a built-in pattern (" +
                              builtin_pattern_list() + ")");
}

}  // namespace yarnhom::yarn
