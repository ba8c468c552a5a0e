#pragma once
// `yarnhom produce`: the yarn RVE dataset of a pattern (Psi and dPsi/ds on every term's grid),
// with sector-based warm starts, a checkpoint that makes a killed run resumable, and the
// dataset file that train-all reads.
#include <string>

namespace yarnhom::yarn {

struct ProduceRunOptions {
  std::string pattern, out, preset = "quick", terms = "all", material, ranges, tile = "1,1";
  int threads = 0, sectors = 8, branch_rounds = 12;
  double branch_tolerance = 0.05;
  double rest_time_limit = 300;
  bool no_warm = false;
  bool no_predictor = false;
  bool fixed_period = false;
};

// Writes the dataset (and removes its checkpoint when every node converged); progress on
// stderr, the report on stdout. Returns the exit status: 0, or 3 when some nodes did not
// converge (listed on stderr; the dataset holds the others).
int run_produce(const ProduceRunOptions& o);

}  // namespace yarnhom::yarn
