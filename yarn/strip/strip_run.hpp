#pragma once
// `yarnhom strip`: a yarn-level fabric strip tiled from a periodic pattern, joined into one
// yarn, clamped at its short ends and stretched quasi-statically (docs/strip.md; supplement
// section 4.2). Resumable per load step.
//
// OUT/settings.txt   what the run is (a rerun with other settings is refused)
// OUT/strip.obj      the generated strip's centrelines (OBJ polylines, m)
// OUT/steps/step_KKK.h5        the equilibrium of load step K (what a resumed run continues from)
// OUT/centrelines/step_KKK.obj its centrelines
// OUT/force.csv      per load step: stretch, force per nominal width (N/m), both clamps' forces,
//                    energy and its parts, iterations, times, closest pair, topology certificate,
//                    and last the force per load width (yarn::Strip::load_width; what accuracy uses)
// The pictures (strip.png, deformed.png, force.png) are drawn by pipeline/strip_command.hpp.
#include <string>

namespace yarnhom::yarn {

struct StripRunOptions {
  std::string pattern, out, size = "0.05,0.10", direction = "course", stretch = "1.0:1.7:0.05", material;
  std::string newton = "trust-region";
  double clamp = 0.005, connector_scale = 1.0 / 200, tolerance = 1e-10, rest_time_limit = 300;
  int max_iterations = 300, threads = 0;
  bool no_bind_off = false, restart = false, verbose = false;
};

// Runs (or resumes) the strip; progress on stderr, the strip and the force table on stdout.
// Returns 0, or 2 when a load step did not converge (or lost its topology certificate): the
// steps before it are kept. Throws std::invalid_argument for bad options or a run folder that
// holds another run.
int run_strip(const StripRunOptions& o);

// The checks run_strip makes before any work (--size, --direction, --newton, --stretch,
// --clamp, --material, the pattern read, the strip's size bounded), without running or writing
// anything: what accuracy and the studies check before their first stage starts. Throws
// std::invalid_argument naming the option and the value.
void check_strip_options(const StripRunOptions& o);

}  // namespace yarnhom::yarn
