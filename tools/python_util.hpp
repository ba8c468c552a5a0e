#pragma once
// Finding the Python helpers: a python3 that imports the given modules ($YARNHOM_PYTHON, then
// /usr/bin/python3 (Debian's python3-matplotlib), then python3 on PATH), and the scripts folder.
#include <cstdlib>
#include <string>
#include <vector>

namespace yarnhom::tools {

inline std::string find_python_with(const std::string& modules) {
  std::vector<std::string> candidates;
  if (const char* e = std::getenv("YARNHOM_PYTHON")) candidates.push_back(e);
  candidates.push_back("/usr/bin/python3");
  candidates.push_back("python3");
  for (const std::string& c : candidates) {
    const std::string cmd = "'" + c + "' -c 'import " + modules + "' >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return c;
  }
  return "";
}

inline std::string scripts_folder() {
  if (const char* e = std::getenv("YARNHOM_SCRIPTS")) return e;
#ifdef YARNHOM_SCRIPTS_DIR
  return YARNHOM_SCRIPTS_DIR;
#else
  return "tools";
#endif
}

}  // namespace yarnhom::tools
