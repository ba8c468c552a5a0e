#include "pipeline/sim_command.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "pipeline/python_env.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

namespace {

void render(const sim::SimRunOptions& o, const sim::SimRunOutcome& r) {
  const std::string py = find_python("matplotlib, numpy");
  const std::string script = (fs::path(scripts_dir()) / "plot" / "render_sim.py").string();
  if (py.empty()) {
    std::fprintf(stderr, "sim: no python3 with matplotlib and numpy (tried $YARNHOM_PYTHON, /usr/bin/python3, python3): "
                         "no PNG written; install python3-matplotlib or set YARNHOM_PYTHON\n");
    return;
  }
  if (!fs::exists(script)) {
    std::fprintf(stderr, "sim: %s not found (set YARNHOM_SCRIPTS to the scripts folder): no PNG written\n", script.c_str());
    return;
  }
  std::string frames;
  for (int f : r.render_frames)
    if (f <= r.result.frames_done) frames += (frames.empty() ? "" : ",") + std::to_string(f);
  // --mp4: a video of every frame (the script says in one line when ffmpeg is absent); not with
  // --render none or --no-frames.
  const std::string cmdline = "'" + py + "' '" + script + "' '" + o.out + "'" +
                              (frames.empty() || o.no_frames ? "" : " --frames " + frames) +
                              (r.render_frames.empty() || o.no_frames ? "" : " --mp4");
  if (std::system(cmdline.c_str()) != 0) std::fprintf(stderr, "sim: the render script failed (%s)\n", cmdline.c_str());
}

}  // namespace

int run_sim_command(const sim::SimRunOptions& o) {
  const sim::SimRunOutcome r = sim::run_sim(o);
  if (!r.render_frames.empty() || !r.result.stretch.empty()) render(o, r);
  return sim::sim_exit_status(r);
}

}  // namespace yarnhom::pipeline
