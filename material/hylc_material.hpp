#pragma once
// HYLC's material format (Sperl et al. 2020; read by ARCSim-HYLC's SplineMaterial), in and
// out, and its evaluation as a full material Psi(s) with gradient and Hessian.
//
//   {"density": rho (kg/m^2),
//    "strain scale": [c0, c1, c2, c3, c4],          scaled strain S_k = s_k / c_k
//    "strain shift": [1, 0, 1, 0, 0],                optional; s_x = |F e1| - 1 (only value accepted)
//    "coeffs": {"const": Psi0,
//               "1D": [{"k", "t": [knots], "p": [values], "m": [slopes]}, ...],
//               "2D": [{"k0", "k1", "tu", "tv", "p", "mu", "mv", "muv"}, ...]}}
//
// k = 0 s_x, 1 s_a, 2 s_y, 3 x-bending, 4 y-bending (our terms 0 1 2 3 5). Knots and slopes are
// in scaled strains; values in J/m^2. 1D: cubic Hermite between knots, linear extrapolation
// from the end knot's value and slope. 2D: bicubic Hermite on the tensor grid, p[i*|tu| + j]
// the value at (tu[j], tv[i]) (u = the k0 strain, fastest), mu = dp/du, mv = dp/dv,
// muv = d2p/dudv (missing muv = 0); outside, in each axis, the tangent extension at the edge
// (so a corner is bilinear: p + mu du + mv dv + muv du dv). An optional "ext" of 1 (constant)
// or 2 (zero) per spline is honoured as ARCSim does. Bending (k = 3, 4, and as second strain
// of a 2D spline) enters through the principal curvatures exactly as for a baked file (spec
// section 8b; material/material.hpp's mixing, umbilic points included).
#include <array>
#include <string>
#include <vector>

#include "material/material.hpp"
#include "core/baked.hpp"

namespace yarnhom {

struct HylcSpline1D {
  int k = 0;
  std::vector<double> t, p, m;
  int ext = 0;
};

struct HylcSpline2D {
  int k0 = 0, k1 = 0;
  std::vector<double> tu, tv, p, mu, mv, muv;
  int ext = 0;
};

struct HylcMaterial {
  double density = 0;
  std::array<double, 5> scale{1, 1, 1, 1, 1};
  double c0 = 0;
  std::vector<HylcSpline1D> d1;
  std::vector<HylcSpline2D> d2;
};

// Refuses (std::invalid_argument naming the file and the key, e.g. "coeffs.2D[3].mu") a file
// that is not JSON, misses a key, has the wrong type or sizes, knots that do not increase, or
// indices out of range.
HylcMaterial read_hylc_material(const std::string& path);
// Writes atomically, numbers with 17 significant digits.
void write_hylc_material(const std::string& path, const HylcMaterial& m);

MaterialEval eval_hylc_material(const HylcMaterial& m, const Strain6& s);

// A baked file in HYLC's format: the knots and Hermite data of every table, with the grid
// extended beyond each box by `margin` times its width on both sides (two extra knots per side,
// sampled from the safeguard), so that within the extended box the HYLC splines evaluate our
// tables and their safeguard exactly; beyond it HYLC's format can only extrapolate linearly.
// Strain scale 1 for the in-plane strains, the largest |bound| of the bending boxes for
// bending.
HylcMaterial hylc_from_baked(const BakedModel& baked, double areal_density, double margin = 0.5);

}  // namespace yarnhom
