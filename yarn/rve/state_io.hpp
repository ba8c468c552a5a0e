#pragma once
// Writing and reading an RVE solution (HDF5), and a tube mesh of the yarns (OBJ) for looking
// at it in any 3D viewer.
//
// State file:
//   /            attrs: format="yarnhom-rve-state", version=1, pattern, units="SI",
//                       strain[6], psi (J/m^2), grad[6], energy (J), converged (0/1),
//                       status, iterations, residual, seconds, material (text),
//                       reference[4] (F0 row-major: the reference tile the strain is measured
//                       from, docs/rve.md section 6; absent in older files = identity)
//   /q           float64 [n, 4]  per vertex: u (local mid-surface frame, m), theta (rad)
//                                 (supplement Eq. 1 layout)
//   /positions   float64 [n, 3]  deformed centreline vertices of the base tile (m)
//   /frames/t    float64 [n, 3]  reference frames the solve used (rest tangents ...)
//   /frames/d1   float64 [n, 3]  (... and directors), and the reference twists:
//   /frames/twist float64 [n]
//   /certificate  attrs: valid (0/1), dmin (m), min_distance (m; -1 if none), moves, failure,
//                        anchor_strain[6] (the strain of the last checked configuration)
//   /certificate/path_strain float64 [m, 6]     the recorded path (when recorded): every
//   /certificate/path_u      float64 [m, n, 3]  configuration from the pattern's own geometry
#include <string>

#include "yarn/rve/energy_density.hpp"

namespace yarnhom::yarn {

inline constexpr const char* kStateFormat = "yarnhom-rve-state";

void write_state(const std::string& path, const RveProblem& rve, const Strain& s,
                 const RveState& state, const DensityResult& result);

// Reads a state to warm start from; refuses (FileError naming file and object) a file of
// another format or of another vertex count than the problem's pattern. The certificate is
// taken as the file states it (yarn/rve/rve_ccd.hpp certify_path re-checks a recorded path); a
// file without one reads as not certified.
RveState read_state(const std::string& path, const RveProblem& rve);

// The reference map F0 a state was solved with (identity for files written before it was
// recorded); build the RveProblem with it before read_state.
Eigen::Matrix2d read_state_reference(const std::string& path);

// Tube mesh: each yarn followed for one period through the periodic images, a ring of
// `sides` vertices around each centreline vertex, radius = the yarn radius.
void write_obj(const std::string& path, const RveProblem& rve, const Strain& s,
               const RveState& state, int sides = 8);

}  // namespace yarnhom::yarn
