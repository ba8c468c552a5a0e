#pragma once
// A certificate that a configuration has the topology of the one a path started from: no pair
// of (non-excluded) yarn segments came closer than d_min anywhere along the path, checked by
// continuous collision detection (numerics/ccd.hpp) on each of its straight moves. Centrelines
// can only pass through each other by meeting (distance 0), so a path that keeps every pair
// above d_min > 0 never passed a yarn through another: the end has the start's topology
// (isotopic as curves; and with d_min a set fraction of the yarn diameter 2r, the yarns never
// overlapped by more than 2r - d_min).
//
// The certificate is what the checks found; it is built up move by move by whoever moves the
// yarns (the Newton solver, a strain change, a predictor) and re-checkable from a recorded
// path (yarn/rve/rve_ccd.hpp: certify_path).
#include <limits>
#include <string>

namespace yarnhom::yarn {

struct ContactCertificate {
  double dmin = 0;   // m: the separation the path was checked against
  bool valid = true; // every move checked so far kept every pair above dmin
  double min_distance = std::numeric_limits<double>::infinity();  // m: smallest closest distance
                                                                  // at a configuration of the path
  int moves = 0;     // straight moves checked since the path's origin
  std::string failure;  // what broke it (the first failure), when not valid
};

// Adds one checked straight move: `safe` the fraction of it that CCD found safe (1: all of it),
// `end_distance` the smallest closest distance at its end configuration, `what` a label for
// the failure message.
void add_move(ContactCertificate& c, double safe, double end_distance, const std::string& what);

// Marks the certificate broken (a move that was not checked, a start below dmin ...).
void invalidate(ContactCertificate& c, const std::string& why);

// One line for reports: "valid: closest 0.93 (2r) over 57 moves, d_min 0.25 (2r)" or the failure.
std::string summary(const ContactCertificate& c, double two_r);

}  // namespace yarnhom::yarn
