#pragma once
// `yarnhom fit-splines`: the HYLC-style baseline, every term of a dataset fitted by a Hermite
// spline with few knots, written as a baked file (accuracy/spline_fit.hpp, docs/accuracy.md).
#include <string>

#include "accuracy/spline_fit.hpp"

namespace yarnhom {

struct FitSplinesOptions {
  std::string data, out;
  SplineFitOptions fit;
  bool no_monotone = false;
};

// Writes the baked file and the per-term table on stdout.
void run_fit_splines(const FitSplinesOptions& o);

}  // namespace yarnhom
