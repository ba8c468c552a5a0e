#include "pipeline/python_env.hpp"

#include <cstdlib>
#include <vector>

#include "pipeline/child_process.hpp"

namespace yarnhom::pipeline {

std::string find_python(const std::string& modules) {
  std::vector<std::string> candidates;
  if (const char* e = std::getenv("YARNHOM_PYTHON")) candidates.push_back(e);
  candidates.push_back("/usr/bin/python3");
  candidates.push_back("python3");
  for (const std::string& c : candidates)
    if (run_child({c, "-c", "import " + modules}, "/dev/null", "/dev/null") == 0) return c;
  return "";
}

std::string scripts_dir() {
  if (const char* e = std::getenv("YARNHOM_SCRIPTS")) return e;
#ifdef YARNHOM_SCRIPTS_DIR
  return YARNHOM_SCRIPTS_DIR;
#else
  return "scripts";
#endif
}

}  // namespace yarnhom::pipeline
