#pragma once
// The stress-free rest state of a pattern (docs/rve.md section 6).
//
// A stored pattern's tile period is the pattern designer's, not the yarns' equilibrium: relaxed
// at that period the tile is pre-stressed (dPsi/ds(0) != 0 in-plane), and a continuum sheet of
// such a material shrinks or grows by itself. relax_tile minimizes the tile's TOTAL energy over
// the fluctuations and the tile's in-plane deformation (s_x, s_a, s_y at II = 0) and returns an
// RVE whose reference is the relaxed tile: s = 0 is then the stress-free state.
//
// Why the total energy E and not the density E / A: an infinite periodic sheet with no load
// has the energy N E_tile for its N tiles, and N is fixed by its yarns; it settles where
// E_tile is stationary under any change of the period. Minimizing E / A instead would let the
// sheet trade energy for area as if the number of tiles could change (it would pull itself
// apart wherever the energy per area falls with stretch). Stationary E in the period means
// zero macroscopic in-plane stress, dE/ds = 0, in any parametrization of the period.
//
// Method: Newton's method on the period, with the fluctuations solved at each step (an
// envelope): for a period s the inner Newton solve gives the equilibrium fluctuations y(s),
// the envelope theorem gives the exact gradient G = dE/ds at fixed y, and the reduced
// (Schur complement) Hessian K = E_ss - E_sy H^-1 E_ys = d/ds G(s, y(s)) comes from central
// differences of G along the equilibrium's sensitivity du/ds (SolveReport::sensitivity, one
// factorization shared by the three directions). We chose this over one Newton solve on the
// joint unknowns (y, s) because it keeps the tested inner solver (definiteness shift, line
// search) untouched, needs no new Hessian blocks, and the outer problem has only 3 unknowns:
// a few outer iterations, each a warm started inner solve of a few Newton steps.
// Each accepted step moves the reference itself, F0 <- F(ds) F0, and re-solves at s = 0 in
// the new reference, so the final state is an equilibrium of the returned RVE exactly.
#include <Eigen/Core>
#include <string>

#include "yarn/rve/newton.hpp"
#include "yarn/rve/rve.hpp"

namespace yarnhom::yarn {

// The upper triangular in-plane map F(s) = [[1+s_x, s_a (1+s_y)], [0, (1+s_y) sqrt(1-s_a^2)]]
// (F^T F = I(s), docs/rve.md section 2) and its inverse (the strain of an upper triangular F
// with positive diagonal).
Eigen::Matrix2d in_plane_map(const Eigen::Vector3d& s);
Eigen::Vector3d in_plane_strain(const Eigen::Matrix2d& F);

// A state of an RVE at the flat strain s, carried into the RVE whose reference is F(s) F0:
// the same positions and frames, now at s = 0 (u and the stored frames turned by the local
// frame's rotation R(s)). Its checked path (anchor, recorded path: flat strains only) is
// carried too, as the same positions in the new reference.
RveState carry_to_reference(const RveState& state, const Strain& flat_strain);

struct RestOptions {
  bool free_period = true;  // false: keep the pattern's own period (the pre-stressed tile)
  double tolerance = 1e-10; // on the in-plane stress |dE/ds| / (EA x total rest length)
  int max_iterations = 40;  // period updates
  double max_step = 0.1;    // largest change of one strain component per update
  SolveOptions solve;       // inner solves (tolerance tightened to 1e-12 at most)
  int first_max_iterations = 500;  // the cold solve at the pattern's own period
  double max_seconds = 0;   // wall-clock guard of the whole relaxation (0: none): a pathological
                            // pattern is refused in bounded time whatever an iteration costs
  bool verbose = false;     // one line per period update on stderr
  bool record_path = false; // record the state's whole path from the pattern (RveState::path)
};

struct RestReport {
  SolveReport first;             // the cold relaxation at the pattern's own period
  SolveReport last;              // the final inner solve, in the relaxed reference
  int iterations = 0;            // period updates accepted
  int inner_iterations = 0;      // Newton iterations of all inner solves, the first included
  double stress = 0;             // final |dE/ds_inplane| / (EA x total rest length)
  Eigen::Vector3d strain = Eigen::Vector3d::Zero();  // (s_x, s_a, s_y) of the relaxed tile
                                                     // relative to the pattern's period
  double seconds = 0;
  bool converged = false;
  std::string summary() const;
};

struct RestTile {
  RveProblem rve;      // reference: the relaxed tile (the pattern's own if !free_period)
  RveState state;      // the rest equilibrium at s = 0 of rve
  RestReport report;
};

// Relaxes the pattern at rest; throws std::runtime_error naming the pattern when the first
// solve or the period relaxation fails.
RestTile relax_tile(const Pattern& pattern, const Material& material, const RestOptions& opt = {},
                    const RveOptions& rve_options = {});

// A state repeated over the copies of tile(pattern, nx, ny) (whose vertices are the
// pattern's, copy after copy): the same configuration in the larger tile. With the same
// reference map, the relaxed rest of a pattern repeated is the rest of its tiling (an RVE-size
// study compares the two under the same strain).
RveState tile_state(const RveState& state, int copies);

// The relaxed rest `one` of `pattern`, repeated nx x ny times: the RVE tile(pattern, nx, ny) in
// one's reference map, with one's state on every copy and one's report. A larger RVE of the same
// material (`rve --tile`, `produce --tile`); a cold relaxation of the patch could settle in
// another local minimum, and its data would no longer extend one tile's.
RestTile repeat_rest(const Pattern& pattern, const RestTile& one, int nx, int ny);

// The in-plane stress measure of RestReport::stress for a dE/ds.
double relative_stress(const RveProblem& rve, const Strain& dEds);

// Mass per unit area of the reference tile, kg/m^2: the yarns' density times their volume
// (pi r^2 times the total REST length: the material length, which stretching does not change)
// over the reference tile's area. The continuum simulator's gravity and inertia.
double areal_density(const RveProblem& rve);

}  // namespace yarnhom::yarn
