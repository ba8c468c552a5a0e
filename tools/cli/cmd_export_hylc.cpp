// yarnhom export-hylc BAKED.h5 -o MATERIAL.json: a baked file in HYLC's material format, so
// that ARCSim-HYLC (and `yarnhom sim`) can load it (material/hylc_export.hpp).
#include "material/hylc_export.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

void register_export_hylc(CLI::App& app) {
  auto [cmd, o] = add_command<HylcExportOptions>(app, "export-hylc");
  cmd->add_option("BAKED", o->baked, "Baked file written by `yarnhom bake`")->required()->check(existing_regular_file());
  add_output_option(cmd, o->out, "The material JSON to write");
  cmd->add_option("--density", o->density,
                  "Areal density in kg/m^2 written as HYLC's \"density\" (default: the baked file's areal_density "
                  "attribute; required when the file has none)")
      ->check(finite_positive());
  cmd->add_option("--margin", o->margin,
                  "Extension of each box on both sides, in box widths (default 0.5; 0: none; else at least 1e-6, "
                  "so that the added knots increase strictly)")
      ->check(CLI::Validator(
          [](std::string& in) -> std::string {
            double v;
            if (!CLI::detail::lexical_cast(in, v) || !std::isfinite(v)) return "'" + in + "' is not a finite number";
            if (v != 0 && !(v >= 1e-6 && v <= 10))
              return "'" + in + "' is out of range: 0, or 1e-6 to 10 (a smaller margin adds knots that do not "
                     "increase strictly)";
            return "";
          },
          "0 or [1e-6, 10]"));
  cmd->callback([o] { export_hylc(*o); });
}

}  // namespace yarnhom::tools
