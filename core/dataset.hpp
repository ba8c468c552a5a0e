#pragma once
// The dataset file (spec section 5): what `produce` (or `synth`) writes and `train-all` reads.
//
//   /                      attrs: format="yarnhom-dataset", version=1, pattern, units="SI", source,
//                                 [areal_density (kg/m^2 of the reference tile)]
//   /rest                  attrs: psi0 (J/m^2), [lattice_original[4], lattice_relaxed[4]
//                                 (m; rows: the tile's two lattice vectors), grad0[6] (dPsi/ds
//                                 at s = 0), hessian[36] (d2Psi/ds2 at s = 0, row-major,
//                                 measured on the RVE: yarn/rve/rest_hessian.hpp), rve_tiles[2]
//                                 (the RVE is the pattern's tile repeated NX x NY; absent: 1 x 1)];
//                                 datasets: q
//                                 (rest solution)
//   /terms/<name>/strain   float64 [N, d]
//   /terms/<name>/energy   float64 [N]
//   /terms/<name>/gradient float64 [N, d]
//   /terms/<name>/raw      float64 [N]
//   /terms/<name>          attrs: indices (int[d]), lower (float[d]), upper (float[d])
#include <cmath>
#include <string>
#include <vector>

#include "core/terms.hpp"

namespace yarnhom {

struct TermData {
  Term term;
  int n = 0;                     // number of samples N
  std::vector<double> strain;    // [N, d] row-major, columns in the order of term.indices
  std::vector<double> energy;    // [N] term target
  std::vector<double> gradient;  // [N, d] gradient target
  std::vector<double> raw;       // [N] Psi(s) - Psi0 before subtracting the 1D terms
  std::vector<double> lower, upper;  // [d] the sampling box
  int dim() const { return term.dim(); }
};

struct Dataset {
  std::string pattern;        // the yarn pattern's name (or "synthetic")
  std::string source;         // "yarn-rve" or "synthetic"; says where the numbers come from
  std::string note;           // free text, e.g. the synthetic energy's definition
  double psi0 = 0.0;          // Psi(0) after relaxation, J/m^2
  std::vector<double> rest_q; // rest solution (may be empty for synthetic data)
  std::vector<TermData> terms;
  // Optional, written since the stress-free rest (docs/produce.md "Dataset file"); files
  // without them still read, the fields then stay empty / NaN (unknown).
  std::vector<double> lattice_original;  // [2, 2] row-major: the pattern tile's lattice vectors
  std::vector<double> lattice_relaxed;   // [2, 2]: the reference tile's (s = 0 is measured there)
  std::vector<double> grad0;             // [6] dPsi/ds at s = 0: ~0 in-plane (stress-free rest),
                                         // the natural bending moment dPsi/dII (J/m)
  std::vector<double> rest_hessian;      // [6, 6] row-major d2Psi/ds2 at s = 0, symmetric; what
                                         // the training holds the networks' curvatures at rest to
  double areal_density = NAN;            // kg/m^2 of the reference tile; NaN: unknown
  std::vector<double> rve_tiles;         // [2] NX, NY (whole numbers >= 1) when the RVE was a patch
                                         // of the pattern's tile; empty: one tile. The lattices and
                                         // rest_q are then the patch's.

  const TermData* find(const std::string& name) const;
};

inline constexpr const char* kDatasetFormat = "yarnhom-dataset";
inline constexpr int kDatasetVersion = 1;
// The most samples one term may have (the paper preset has 961 per 2D term).
inline constexpr size_t kMaxSamples = 10000000;

// Reads and validates; throws FileError naming the file, the object and the problem for a
// missing or non-HDF5 file, a wrong format tag, missing groups, wrong shapes, non-finite
// values, fewer than 2 samples, an unknown term, or a box with lower >= upper.
Dataset read_dataset(const std::string& path);

// Checks the same invariants on an in-memory dataset (file is used in messages only).
void validate_dataset(const Dataset& ds, const std::string& file);

// Writes atomically (temporary name, then rename).
void write_dataset(const std::string& path, const Dataset& ds);

}  // namespace yarnhom
