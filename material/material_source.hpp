#pragma once
// Loads the material a simulation runs: a baked file (`yarnhom bake`, HDF5) or a HYLC material
// JSON (material/hylc_material.hpp), told apart by content. The areal density comes with it when
// the file carries one: the baked file's root attribute `areal_density` (kg/m^2, carried from
// the dataset through the model by produce/train-all/bake), HYLC's "density". Either way fn is
// the material with its collapse guard (material/collapse_guard.hpp): around the baked terms'
// boxes, or around the HYLC 1D splines' knot ranges.
#include <optional>
#include <string>

#include "material/material_fn.hpp"

namespace yarnhom {

struct LoadedMaterial {
  MaterialFn fn;
  MaterialValueFn value;                // fn's psi alone (baked files; empty for HYLC: use fn)
  std::optional<double> areal_density;  // kg/m^2
  std::string kind;                     // "baked" or "hylc"
  std::string missing_terms;            // baked: terms absent from the file (count as zero)
  std::shared_ptr<const CollapseGuard> guard;  // in fn (material/collapse_guard.hpp)
};

// Throws (naming the file) when it is neither, or is a model file that has not been baked.
LoadedMaterial load_material(const std::string& path);

}  // namespace yarnhom
