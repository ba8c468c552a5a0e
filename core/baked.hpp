#pragma once
// The baked file (spec section 8), written by `yarnhom bake`, read by the baked evaluator
// (material/baked_eval.hpp) and so by a cloth simulator. Every term is a Hermite table over its
// box; outside the box the safeguard extends it (docs/bake.md has the formulas).
//
//   /                       attrs: format="yarnhom-baked", version=1, model, dataset,
//                                  psi0 (J/m^2), psi0_known (1 when psi0 came from the dataset),
//                                  [areal_density (kg/m^2; absent: unknown)]
//   /tables/<name>          attrs: indices, lower, upper, knots (int[d]), and as in the model
//                                  file: activation, hidden, in_center, in_halfwidth, out_mean,
//                                  out_std, epochs, backend, status,
//                                  extrapolation ("safeguard" when absent, or "linear")
//   1D  /tables/<name>/f, f_x                 float64 [n]        knot i at lower + i h
//       attrs safeguard_lower, safeguard_upper  [a, b, c]: a s^2 + b s + c beyond that end
//   2D  /tables/<name>/f, f_x, f_y, f_xy      float64 [n0, n1]   knot (i, j) at (x_i, y_j);
//                                  x is the term's first strain, y its second
//       /tables/<name>/safeguard/edge_x_lower, edge_x_upper   float64 [n1, 6]
//       /tables/<name>/safeguard/edge_y_lower, edge_y_upper   float64 [n0, 6]
//           per knot along the edge: g0, g0', g1, g1', g2, g2' with g0, g1 = f, df/dn on the
//           edge (n the edge's own axis, not the outward normal), g2 the band's curvature
//           (0: first order, docs/bake.md; an older bake stored a rising curvature there),
//           and ' along the edge
//       /tables/<name>/safeguard/corner_<x>_<y>  ( <x>,<y> in lower|upper )  float64 [8]
//           a00 a10 a01 a20 a11 a02 a21 a12: a00 a10 a01 a11 the table's partials at the
//           corner, a20 a21 (a02 a12) the x (y) edge's g2, g2' at the corner
//
// extrapolation = "linear" (tables fitted by `fit-splines`, HYLC's convention): outside the box
// the table continues to first order only, i.e. the same stored coefficients with every
// second-order part zero (1D a = 0; 2D edges g2 = g2' = 0; corners a20 = a02 = a21 = a12 = 0),
// so the formulas of docs/bake.md evaluate it unchanged: f + f_n dn in an edge band and
// f + f_x dx + f_y dy + f_xy dx dy in a corner.
//
// The safeguard coefficients are derived from the knots (the evaluator recomputes them and
// checks that they agree); they are stored so that a reader without this library can
// evaluate the extension from docs/bake.md alone.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "core/terms.hpp"

namespace yarnhom {

inline constexpr const char* kBakedSafeguard = "safeguard";
inline constexpr const char* kBakedLinear = "linear";

struct BakedTable {
  Term term;
  std::vector<double> lower, upper;  // [d] the box the table covers
  std::vector<int> knots;            // [d] knots per axis (>= 2)
  // Knot data in physical units. 1D: f, f_x of size n. 2D: row-major [n0, n1].
  std::vector<double> f, f_x, f_y, f_xy;
  // Provenance, copied from the model file.
  NetworkDesc desc;
  Normalization norm;
  int epochs = 0;
  std::string backend, status;
  // How the table continues outside its box: kBakedSafeguard (spec section 8) or kBakedLinear.
  std::string extrapolation = kBakedSafeguard;
  // Safeguard coefficients. 1D: [a, b, c] per end. 2D: edges in the order x_lower, x_upper,
  // y_lower, y_upper ([n_along, 6] row-major), corners in the order (x lower, y lower),
  // (x upper, y lower), (x lower, y upper), (x upper, y upper) ([8] each).
  std::array<double, 3> safeguard_lower{}, safeguard_upper{};
  std::array<std::vector<double>, 4> edges;
  std::array<std::array<double, 8>, 4> corners{};

  int dim() const { return term.dim(); }
  size_t num_knots() const { return dim() == 1 ? size_t(knots[0]) : size_t(knots[0]) * knots[1]; }
  double spacing(int axis) const { return (upper[axis] - lower[axis]) / (knots[axis] - 1); }
};

inline constexpr std::array<const char*, 4> kBakedEdgeNames = {"edge_x_lower", "edge_x_upper",
                                                               "edge_y_lower", "edge_y_upper"};
inline constexpr std::array<const char*, 4> kBakedCornerNames = {
    "corner_lower_lower", "corner_upper_lower", "corner_lower_upper", "corner_upper_upper"};

struct BakedModel {
  std::string model;    // the model file it was baked from
  std::string dataset;  // that model's dataset
  double psi0 = 0.0;    // Psi(0), J/m^2 (0 when unknown)
  bool psi0_known = false;
  double areal_density = NAN;  // kg/m^2 of the reference tile (gravity, inertia); NaN: unknown
  std::vector<BakedTable> tables;  // in catalogue order (core/terms.hpp)
  const BakedTable* find(const std::string& name) const;
};

inline constexpr const char* kBakedFormat = "yarnhom-baked";
// The safeguard's g2 and corner a20 a21 a02 a12 are the clamped continuation's (docs/bake.md),
// not the table's raw partials since issue 12; the layout is unchanged, so the version is too.
// A file baked before then whose boundary curved down disagrees with the recomputed
// coefficients, and the evaluator says so (bake it again).
inline constexpr int kBakedVersion = 1;
// The most knots per axis a table may have (bake's --res1d and --res2d limits).
inline constexpr int kMaxKnots1D = 1000000;
inline constexpr int kMaxKnots2D = 10000;

// True when the file is HDF5 with the baked format tag (false for a model file, or any other).
bool is_baked_file(const std::string& path);

// Reads and checks shapes, finiteness and boxes; throws FileError naming the file, the object
// and the problem. (Agreement of the safeguard coefficients with the knots is checked by the
// evaluator, material/baked_eval.hpp, which can recompute them.)
BakedModel read_baked(const std::string& path);
// Checks the same invariants in memory (file is used in messages only).
void validate_baked(const BakedModel& m, const std::string& file);
// Writes atomically (temporary name, then rename).
void write_baked(const std::string& path, const BakedModel& m);

}  // namespace yarnhom
