#pragma once
// `yarnhom sim`: the simulation (sim/sim_run.hpp), then the PNG renders of its frames and, for
// stretch, its force curve (scripts/plot/render_sim.py, when a python3 with matplotlib and numpy
// is found).
#include "sim/sim_run.hpp"

namespace yarnhom::pipeline {

// The exit status: 0, or 3 when the simulation stopped on an unphysical strain or became
// non-finite (sim::sim_exit_status).
int run_sim_command(const sim::SimRunOptions& o);

}  // namespace yarnhom::pipeline
