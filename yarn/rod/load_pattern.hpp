#pragma once
// A pattern as the commands take it (rve, produce, strip): a .pyp file, or the name of a built-in
// pattern (yarn/rod/generate.hpp).
#include <string>

#include "yarn/rod/pattern.hpp"

namespace yarnhom::yarn {

// An existing path is read as a .pyp file (refused unless a regular file: a FIFO would block the
// reader); otherwise a built-in name; otherwise std::invalid_argument listing the built-in names.
Pattern load_pattern(const std::string& name_or_path);

}  // namespace yarnhom::yarn
