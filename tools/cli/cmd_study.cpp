// yarnhom study table5 | bake-resolution | strip-width | rve-size: the supplement's accuracy
// tables as commands (docs/accuracy.md; pipeline/study.hpp). Each runs the accuracy test for
// several patterns, directions or materials, cached and resumable stage by stage.
#include <cstdio>
#include <stdexcept>

#include "pipeline/study.hpp"
#include "tools/cli/accuracy_options.hpp"
#include "tools/cli/cli_util.hpp"

namespace yarnhom::tools {

namespace {

// A study: its own options, then the accuracy test's; the callback runs it.
// `check` makes the accuracy test's checks (tools/cli/accuracy_options.hpp) for every pattern,
// direction and size the study will run, before its first stage.
template <class Options>
void add_study(CLI::App* study, const std::string& name, void (*add_own)(CLI::App*, Options&),
               void (*run)(const Options&), void (*check)(const Options&), const AccuracyOptionHelp& help = {}) {
  auto [cmd, o] = add_command<Options>(*study, name);
  add_own(cmd, *o);
  add_accuracy_options(cmd, o->acc, help);
  cmd->callback([o, run, check] {
    check(*o);
    run(*o);
  });
}

void check_table5(const pipeline::Table5Options& o) { check_accuracy_run(o.acc, o.patterns, o.directions, {o.acc.size}); }
void check_bake_resolution(const pipeline::BakeResolutionOptions& o) {
  check_accuracy_run(o.acc, {o.pattern}, {o.direction}, {o.acc.size});
}
void check_rve_size(const pipeline::RveSizeOptions& o) { check_accuracy_run(o.acc, {o.pattern}, {o.direction}, {o.acc.size}); }
void check_strip_width(const pipeline::StripWidthOptions& o) {
  pipeline::AccuracyOptions a = o.acc;
  a.dataset = o.dataset;
  a.baked = o.baked;
  for (double w : o.widths) {
    char sz[64];
    std::snprintf(sz, sizeof sz, "%.6g,%.6g", w, o.length);  // as the study passes them
    try {
      check_accuracy_run(a, {o.pattern}, {o.direction}, {sz});
    } catch (const std::exception& e) {  // the study's own options, not only the stage's --size they became
      char what[96];
      std::snprintf(what, sizeof what, "--widths %g with --length %g: ", w, o.length);
      throw std::invalid_argument(what + std::string(e.what()));
    }
  }
}

void add_table5_options(CLI::App* cmd, pipeline::Table5Options& o) {
  cmd->add_option("PATTERNS", o.patterns,
                  "Pattern files (.pyp) or built-in names (" + yarn::builtin_pattern_list() +
                      "); the paper's Table 5: basket stockinette slip_stitch_honeycomb.pyp cartridge_belt_rib.pyp "
                      "(the last two the published files, README 'Patterns')")
      ->required();
  cmd->add_option("--directions", o.directions, "Directions to test (comma-separated or repeated)")->delimiter(',')->check(CLI::IsMember({"course", "wale"}))->capture_default_str();
  add_output_option(cmd, o.out, "Output folder (created)");
}

void add_bake_resolution_options(CLI::App* cmd, pipeline::BakeResolutionOptions& o) {
  add_pattern_argument(cmd, o.pattern, "Pattern file (.pyp) or built-in name");
  add_direction_option(cmd, o.direction)->capture_default_str();
  add_output_option(cmd, o.out, "Output folder (created)");
  cmd->add_option("--reference-res1d", o.reference_res1d,
                  "Knots of a 1D table of the reference bake, the row that stands for the unbaked network (fine "
                  "enough by default; smaller only for a quick check of the command)")
      ->check(CLI::Range(2, 1000000))
      ->capture_default_str();
  cmd->add_option("--reference-res2d", o.reference_res2d, "Knots per axis of a 2D table of the reference bake (as above)")
      ->check(CLI::Range(2, 10000))
      ->capture_default_str();
}

void add_strip_width_options(CLI::App* cmd, pipeline::StripWidthOptions& o) {
  add_pattern_argument(cmd, o.pattern, "Pattern (.pyp file or built-in name)");
  add_direction_option(cmd, o.direction)->capture_default_str();
  cmd->add_option("--widths", o.widths, "Strip widths in metres (comma-separated or repeated)")
      ->delimiter(',')
      ->check(finite_positive())
      ->capture_default_str();
  cmd->add_option("--length", o.length, "Strip length in metres (along the stretch)")->check(finite_positive())->capture_default_str();
  add_reuse_options(cmd, o.dataset, o.baked);
  add_output_option(cmd, o.out, "Output folder (created)");
  cmd->add_flag("--no-plot", o.no_plot, "Write no PNG");
}

void add_rve_size_options(CLI::App* cmd, pipeline::RveSizeOptions& o) {
  add_pattern_argument(cmd, o.pattern, "Pattern (.pyp file or built-in name)");
  cmd->add_option("--tiles", o.tiles, "Patch sizes n (n x n tiles; comma-separated or repeated)")->delimiter(',')->check(CLI::Range(1, 8))->capture_default_str();
  add_direction_option(cmd, o.direction)->capture_default_str();
  add_output_option(cmd, o.out, "Output folder (created)");
}

}  // namespace

void register_study_accuracy(CLI::App& app) {
  CLI::App* study = study_group(app, "Studies that reproduce the supplement's tables (docs/accuracy.md)");
  add_study<pipeline::Table5Options>(study, "table5", add_table5_options, pipeline::run_study_table5, check_table5);
  add_study<pipeline::BakeResolutionOptions>(study, "bake-resolution", add_bake_resolution_options,
                                             pipeline::run_study_bake_resolution, check_bake_resolution);
  AccuracyOptionHelp width_help;
  width_help.size.clear();  // the study sets each strip's size (--widths, --length)
  add_study<pipeline::StripWidthOptions>(study, "strip-width", add_strip_width_options, pipeline::run_study_strip_width,
                                         check_strip_width, width_help);
  add_study<pipeline::RveSizeOptions>(study, "rve-size", add_rve_size_options, pipeline::run_study_rve_size, check_rve_size);
}

}  // namespace yarnhom::tools
