// yarnhom export-hylc BAKED.h5 -o MATERIAL.json: a baked file in HYLC's material format, so
// that ARCSim-HYLC (and `yarnhom sim`) can load it (sim/hylc_material.hpp has the format).
#include <cstdio>

#include "core/baked.hpp"
#include "sim/hylc_material.hpp"
#include "sim/material_source.hpp"
#include "tools/commands.hpp"

namespace yarnhom::tools {

void register_export_hylc(CLI::App& app) {
  struct Opts {
    std::string baked, out;
    double density = 0, margin = 0.5;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "export-hylc",
      "Write a baked file in HYLC's material JSON format (density, strain scale, const, 1D and 2D Hermite "
      "splines), which ARCSim-HYLC loads. Every table keeps its knots; the grid is extended beyond each box "
      "by --margin times its width so that the safeguard is reproduced exactly there (HYLC's format "
      "extrapolates linearly beyond its last knot).");
  cmd->add_option("BAKED", o->baked, "Baked file written by `yarnhom bake`")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->out, "The material JSON to write")->required();
  cmd->add_option("--density", o->density,
                  "Areal density in kg/m^2 written as HYLC's \"density\" (default: the baked file's areal_density "
                  "attribute; required when the file has none)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--margin", o->margin, "Extension of each box on both sides, in box widths (default 0.5)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->callback([o] {
    const BakedModel baked = read_baked(o->baked);
    double rho = o->density;
    if (!(rho > 0)) {
      const sim::LoadedMaterial lm = sim::load_material(o->baked);
      if (!lm.areal_density)
        throw std::invalid_argument(o->baked + ": no areal_density attribute; give --density KG_PER_M2 (HYLC's format needs one)");
      rho = *lm.areal_density;
    }
    const sim::HylcMaterial m = sim::hylc_from_baked(baked, rho, o->margin);
    sim::write_hylc_material(o->out, m);
    std::fprintf(stderr, "export-hylc: %zu 1D and %zu 2D splines, density %g kg/m^2 -> %s\n", m.d1.size(), m.d2.size(),
                 rho, o->out.c_str());
  });
}

}  // namespace yarnhom::tools
