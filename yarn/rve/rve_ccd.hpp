#pragma once
// Collision checks of the periodic RVE (numerics/ccd.hpp on the RVE's segments): the closest
// distance between yarn segments in a configuration, and continuous collision detection
// along a straight move between two configurations, over every pair the contact energy
// would see (a base-tile segment and a segment of any periodic image, each unordered pair
// once, the same exclusions as contact: RveProblem::excluded).
//
// A configuration is (s, state): vertex v of the image at tile offset o sits at
// Phi(X_v + o p, h_v) + R u_v (docs/rve.md section 2). A *straight move* between two
// configurations moves every point of every image along the line between its two positions.
// At equal strains that is exactly the path of a Newton step (x is linear in u); between
// different strains it is one admissible continuous path between the two configurations
// (the linear interpolation of two periodic point sets is periodic with the interpolated
// lattice; under curvature, of each image's points). A path that keeps every pair above
// d_min proves that the end configuration has the start's topology, whichever path the
// solver itself took.
#include <vector>

#include "yarn/rod/contact_certificate.hpp"
#include "yarn/rve/rve.hpp"

namespace yarnhom::yarn {

struct RveMoveCheck {
  double t = 1;                  // the move is safe on [0, t] (1: all of it)
  double start_distance = 0;     // smallest closest distance at the start (m) among pairs
  double end_distance = 0;       // within `reach` (see check_move); +inf when none is
  int pairs = 0;                 // candidate pairs checked by CCD
  int images = 0;                // periodic images that took part
};

// CCD of the straight move from (s0, st0) to (s1, st1) against dmin. `reach` (>= dmin) is the
// distance within which pairs are looked at (for the start/end distances reported).
RveMoveCheck check_move(const RveProblem& rve, const Strain& s0, const RveState& st0, const Strain& s1,
                        const RveState& st1, double dmin, double reach);

// The smallest closest distance between non-excluded segment pairs of one configuration,
// +inf if no pair is within `reach`.
double min_separation(const RveProblem& rve, const Strain& s, const RveState& st, double reach);

// Re-checks a recorded path from scratch: it must start at the pattern's own geometry
// (u = 0 at RveProblem::pattern_strain(): RveProblem::initial_state's anchor) and every straight move between consecutive
// points must keep every pair above dmin. Returns the certificate those checks give.
ContactCertificate certify_path(const RveProblem& rve, const std::vector<PathPoint>& path, double dmin);

}  // namespace yarnhom::yarn
