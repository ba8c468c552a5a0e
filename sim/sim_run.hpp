#pragma once
// `yarnhom sim`: a built-in scene (drape, hang, stretch) or a scene file with a baked material
// (or HYLC's material JSON), the command line's overrides applied; progress and the summary on
// stderr. The renders are drawn by pipeline/sim_command.hpp (a Python script).
#include <string>
#include <vector>

#include "sim/simulation.hpp"

namespace yarnhom::sim {

struct SimRunOptions {
  std::string scene, out, material, integrator, direction = "course", solver = "auto", render, hessian = "split";
  std::string size, stretch, tol_norm, eigen_filter = "clamp", self_collision;  // self_collision: "", "on", "off"
  std::string body;  // tshirt: a body OBJ instead of the mannequin
  double clamp = -1;
  double dhat = 0;
  double pcg_tolerance = 1e-3;  // --solver pcg / pcg-cuda
  double density = 0, dt = 0, tol = 0, alpha = -1, beta = -1, air = -1, friction = -1, eps_v = 0;
  int friction_updates = -1;
  int factor_reuse = -1;        // -1: the scene's (sim/newton.hpp, NewtonSettings::reuse_cg)
  double factor_reuse_tol = 0;  // 0: the scene's
  int resolution = 0, frames = 0, substeps = 0, max_iterations = 0, threads = 0, blas_threads = 0;
  bool no_frames = false, profile = false, quiet = false;
};

struct SimRunOutcome {
  std::string scene;               // its name
  std::vector<int> render_frames;  // the frames to draw as PNG
  SimResult result;
};

// Runs the simulation into o.out (frames, steps.csv, stretch.csv, scene_info.json).
SimRunOutcome run_sim(const SimRunOptions& o);

// The checks run_sim makes of its options and scene before any work (the scene built with the
// command line's overrides, --material a regular file when given), without running or writing
// anything: what accuracy and the studies check before their first stage starts.
void check_sim_options(const SimRunOptions& o);

// 0, or 3 (saying why on stderr) when the run stopped on an unphysical strain or became
// non-finite.
int sim_exit_status(const SimRunOutcome& r);

}  // namespace yarnhom::sim
