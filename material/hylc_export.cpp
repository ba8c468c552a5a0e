#include "material/hylc_export.hpp"

#include <cstdio>
#include <stdexcept>

#include "core/baked.hpp"
#include "core/console.hpp"
#include "material/hylc_material.hpp"
#include "material/material_source.hpp"

namespace yarnhom {

void export_hylc(const HylcExportOptions& o) {
  // -o must not be the input (by device and inode: a symbolic or hard link to it included);
  // the JSON is written atomically, so a failed export leaves the previous output as it was.
  prepare_output(o.out, {o.baked}, "-o");
  const BakedModel baked = read_baked(o.baked);
  double rho = o.density;
  if (!(rho > 0)) {
    const LoadedMaterial lm = load_material(o.baked);
    if (!lm.areal_density)
      throw std::invalid_argument(o.baked + ": no areal_density attribute; give --density KG_PER_M2 (HYLC's format needs one)");
    rho = *lm.areal_density;
  }
  const HylcMaterial m = hylc_from_baked(baked, rho, o.margin);
  write_hylc_material(o.out, m);
  std::fprintf(stderr, "export-hylc: %zu 1D and %zu 2D splines, density %g kg/m^2 -> %s\n", m.d1.size(), m.d2.size(),
               rho, o.out.c_str());
}

}  // namespace yarnhom
