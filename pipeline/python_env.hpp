#pragma once
// Where the plotting scripts are and which Python runs them (plot, sim, strip and the studies).
#include <string>

namespace yarnhom::pipeline {

// A python3 that imports `modules`: $YARNHOM_PYTHON, then the system's /usr/bin/python3
// (Debian's python3-matplotlib), then python3 on PATH. Empty if none.
std::string find_python(const std::string& modules = "matplotlib, h5py, numpy");

// The folder holding plot/*.py: $YARNHOM_SCRIPTS, else the source tree's scripts/.
std::string scripts_dir();

}  // namespace yarnhom::pipeline
