#pragma once
// `yarnhom plot RUN_DIR`: the pictures of a run (supplement Fig. 1, 3, 4 and 1D fits). The
// numbers are computed by pipeline/plot_data.hpp with the project's own evaluators and written to
// RUN_DIR/plots/plotdata.h5; scripts/plot/plot_run.py only draws them (matplotlib, h5py), so
// that no formula exists twice.
#include <string>

namespace yarnhom::pipeline {

struct PlotOptions {
  std::string run, model, baked, data, out;  // "" = RUN_DIR/model.h5, baked.h5, dataset.h5, plots/
};

// Returns the exit status: 0, 2 without a suitable python, 1 when the script failed.
int run_plot(const PlotOptions& o);

}  // namespace yarnhom::pipeline
