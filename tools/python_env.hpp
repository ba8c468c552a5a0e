#pragma once
// Where the plotting scripts are and which Python runs them (shared by `plot` and `study`).
#include <cstdlib>
#include <string>
#include <vector>

#include "tools/child_process.hpp"

namespace yarnhom::tools {

// A python3 that imports `modules`: $YARNHOM_PYTHON, then the system's /usr/bin/python3
// (Debian's python3-matplotlib), then python3 on PATH. Empty if none.
inline std::string find_python(const std::string& modules = "matplotlib, h5py, numpy") {
  std::vector<std::string> candidates;
  if (const char* e = std::getenv("YARNHOM_PYTHON")) candidates.push_back(e);
  candidates.push_back("/usr/bin/python3");
  candidates.push_back("python3");
  for (const std::string& c : candidates)
    if (run_child({c, "-c", "import " + modules}, "/dev/null", "/dev/null") == 0) return c;
  return "";
}

// The folder holding plot/*.py: $YARNHOM_SCRIPTS, else the source tree's tools/ (shared by
// plot, sim, strip and the studies).
inline std::string scripts_dir() {
  if (const char* e = std::getenv("YARNHOM_SCRIPTS")) return e;
#ifdef YARNHOM_SCRIPTS_DIR
  return YARNHOM_SCRIPTS_DIR;
#else
  return "tools";
#endif
}

}  // namespace yarnhom::tools
