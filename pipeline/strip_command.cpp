#include "pipeline/strip_command.hpp"

#include <cstdio>
#include <filesystem>

#include "pipeline/child_process.hpp"
#include "pipeline/python_env.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

int run_strip_command(const StripCommandOptions& o) {
  const int status = yarn::run_strip(o);
  if (o.no_plots) return status;
  const std::string py = find_python();
  const std::string script = (fs::path(scripts_dir()) / "plot" / "plot_strip.py").string();
  if (py.empty() || !fs::exists(script)) {
    std::fprintf(stderr,
                 "yarnhom strip: no python3 with matplotlib, h5py and numpy (tried $YARNHOM_PYTHON, /usr/bin/python3, "
                 "python3), or no %s: no PNGs; the numbers are in %s\n",
                 script.c_str(), o.out.c_str());
    return status;
  }
  // A child without a shell that dies with this process (pipeline/child_process.hpp).
  const int rc = run_child({py, script, o.out});
  if (rc != 0) std::fprintf(stderr, "yarnhom strip: the plot script %s failed (exit status %d)\n", script.c_str(), rc);
  else std::printf("pictures    strip.png, deformed.png, force.png\n");
  return status;
}

}  // namespace yarnhom::pipeline
