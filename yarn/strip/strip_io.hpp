#pragma once
// Files of the strip test (docs/strip.md): centrelines as OBJ polylines, and one HDF5
// checkpoint per load step (what a resumed run continues from). Every file is written under a
// temporary name and renamed into place when complete: an interrupted run leaves either the
// old file or the new one, never half of one.
//
// OBJ: `v x y z` (m) per vertex in yarn order, then the yarn as polylines `l i j k ...`
// (1-based), one per run of yarn (group `yarn`) or boundary yarn (group `boundary`);
// consecutive runs share their end vertex, so the union is the one yarn.
//
// Step file (HDF5):
//   /        attrs: format="yarnhom-strip-step", version=1, units="SI", strip (name),
//                   stretch, force_low, force_high, force (N), tension (N/m), energy (J),
//                   min_distance (closest segment pair / 2r), status, iterations, residual,
//                   seconds, assembly_seconds, factor_seconds, line_search_seconds
//   /x            float64 [n, 3]   vertex positions (m)
//   /theta        float64 [n-1]    twist angle per edge (rad)
//   /frames/t     float64 [n-1, 3] reference frames the next solve uses (tangents ...)
//   /frames/d1    float64 [n-1, 3] (... and directors)
//   /frames/twist float64 [n]      reference twist per joint (rad)
//   /certificate  attrs: valid (0/1), dmin (m), min_distance (m; -1: none within reach),
//                 moves, failure: the topology certificate of every move from the generated
//                 strip to this equilibrium (yarn/rod/contact_certificate.hpp); a file without it
//                 reads back as not certified
#include <string>
#include <vector>

#include "yarn/strip/strip_stretch.hpp"

namespace yarnhom::yarn {

inline constexpr const char* kStripStepFormat = "yarnhom-strip-step";

void write_centrelines(const std::string& path, const Strip& s, const std::vector<Eigen::Vector3d>& x);

struct Polylines {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::vector<int>> lines;  // 0-based vertex indices
};
// Reads `v` and `l` records of an OBJ file (other records ignored); refuses malformed ones
// naming the file and line.
Polylines read_polylines(const std::string& path);

void write_step(const std::string& path, const Strip& s, const StretchStep& step, const StripState& st);
// Refuses (FileError naming file and object) a file of another format or another strip size.
StretchStep read_step(const std::string& path, const StripProblem& P, StripState& st);

}  // namespace yarnhom::yarn
