#pragma once
// `yarnhom strip`: the yarn-level strip stretch test (yarn/strip/strip_run.hpp), then its
// pictures strip.png, deformed.png and force.png (scripts/plot/plot_strip.py, when a python3
// with matplotlib is found).
#include "yarn/strip/strip_run.hpp"

namespace yarnhom::pipeline {

struct StripCommandOptions : yarn::StripRunOptions {
  bool no_plots = false;
};

// The exit status of yarn::run_strip (0, or 2 when a load step failed: the pictures show the
// steps before it).
int run_strip_command(const StripCommandOptions& o);

}  // namespace yarnhom::pipeline
