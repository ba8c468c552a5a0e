#pragma once
// `yarnhom export-hylc`: a baked file in HYLC's material JSON (material/hylc_material.hpp), so
// that ARCSim-HYLC (and `yarnhom sim`) can load it.
#include <string>

namespace yarnhom {

struct HylcExportOptions {
  std::string baked, out;
  double density = 0;   // kg/m^2; 0: the baked file's areal_density
  double margin = 0.5;  // box widths the grid extends beyond each box
};

// Writes the JSON and one line on stderr.
void export_hylc(const HylcExportOptions& o);

}  // namespace yarnhom
