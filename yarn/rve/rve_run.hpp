#pragma once
// `yarnhom rve`: the yarn RVE of a pattern at one macroscopic strain: Psi, dPsi/ds, the solver's
// report; optionally the equilibrium state (HDF5), a tube mesh of the yarns (OBJ), the relaxed
// pattern (.pyp) and the Hessian at rest; or the re-check of a state file's certificate.
#include <string>

namespace yarnhom::yarn {

struct RveRunOptions {
  std::string pattern, strain = "0,0,0,0,0,0", material, out, obj, start, pattern_out, certify, tile = "1,1",
      energy_map;
  bool json = false, verbose = false, fixed_period = false, no_ccd = false, rest_hessian = false;
  double tolerance = 1e-10, time_limit = 300;
  int max_iterations = 500;
};

// Prints the result (text or one JSON object) on stdout. Returns the exit status: 0, 2 when the
// solve did not converge, 3 when the result (or the --certify path) is not certified.
int run_rve(const RveRunOptions& o);

}  // namespace yarnhom::yarn
