#pragma once
// Yarn material parameters (SI). Defaults and their sources: docs/yarn_material.md.
#include <string>
#include <vector>

namespace yarnhom::yarn {

// The defaults are "hylc-calibrated" (docs/yarn_material.md): the yarn density HYLC's fitted
// materials were made with, and moduli calibrated so that the RVE's Psi along s_x and s_y
// matches HYLC's own fitted energies of the paper's stockinette and basket.
struct Material {
  double young = 9.7e4;              // Young's modulus E, Pa (stretching EA, bending EI)
  double shear = 9.7e4 / 3.0;        // shear modulus G, Pa (twisting GJ); E/(2(1+nu)), nu = 0.5
  double density = 120;              // kg/m^3 of the yarn: the areal density (yarn/rve/rest.hpp)
  double contact_stiffness = 9.7e5;  // Pa; contact energy scale k_c = contact_stiffness * radius
  bool slide_constraint = true;      // pin each yarn's sliding along itself (section "zero modes")
};

// Reads "key = value" lines (# comments, blank lines allowed; keys: young, shear, density,
// contact_stiffness, slide_constraint). Unknown keys, non-numbers and non-positive moduli are
// refused with the file and the line.
Material read_material(const std::string& path);
Material parse_material(const std::string& text, const std::string& file);
std::string format_material(const Material& m);

// Named materials (docs/yarn_material.md; the same values as yarn/rod/materials/<name>.txt):
// "hylc-calibrated", the default (Material{}), and "yarnhom-2025", the constants used before it.
std::vector<std::string> builtin_material_names();
bool is_builtin_material(const std::string& name);
Material builtin_material(const std::string& name);  // throws std::invalid_argument
// `what` names a material file if one exists there, else a built-in material; anything else is
// refused, naming the known names.
Material load_material(const std::string& what);

}  // namespace yarnhom::yarn
