#pragma once
// Yarn material parameters (SI). Defaults and their sources: docs/yarn_material.md.
#include <string>

namespace yarnhom::yarn {

struct Material {
  double young = 1.0e6;            // Young's modulus E, Pa (stretching EA, bending EI)
  double shear = 1.0e6 / 3.0;      // shear modulus G, Pa (twisting GJ); E/(2(1+nu)), nu = 0.5
  double density = 1.2e3;          // kg/m^3; unused by the quasi-static RVE, kept for the record
  double contact_stiffness = 1.0e6;  // Pa; contact energy scale k_c = contact_stiffness * radius
  bool slide_constraint = true;    // pin each yarn's sliding along itself (section "zero modes")
};

// Reads "key = value" lines (# comments, blank lines allowed; keys: young, shear, density,
// contact_stiffness, slide_constraint). Unknown keys, non-numbers and non-positive moduli are
// refused with the file and the line.
Material read_material(const std::string& path);
Material parse_material(const std::string& text, const std::string& file);
std::string format_material(const Material& m);

}  // namespace yarnhom::yarn
