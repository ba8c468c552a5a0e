#pragma once
// A smooth analytic energy density Psi(s) of the 6-strain, standing in for the yarn producer
// in tests, benchmarks and the demo (docs/synthetic.md writes it out). Datasets made from it
// say so in their attributes (source = "synthetic").
#include <string>

#include "core/dataset.hpp"

namespace yarnhom {

// Psi(s) in J/m^2 and, if grad is given, dPsi/ds.
double synthetic_psi(const double s[6], double grad[6] = nullptr);

// The spec's dataset for all 14 terms. preset "paper": 100 points per 1D term and a 31 x 31
// grid per 2D term; "quick": 21 and 9 x 9. Boxes: HYLC's defaults with bending range 200/m.
Dataset make_synthetic_dataset(const std::string& preset);

// The energy's definition, as stored in the dataset's note attribute.
extern const char* const kSyntheticDefinition;

}  // namespace yarnhom
