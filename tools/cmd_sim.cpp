// yarnhom sim SCENE -o OUT: simulate cloth with a baked material (or a HYLC material JSON):
// built-in scenes drape, hang, stretch, or a scene file (sim/scene_json.hpp, docs/sim.md).
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/blas_threads.hpp"
#include "core/heap_policy.hpp"
#include "sim/material_source.hpp"
#include "sim/scene_json.hpp"
#include "sim/simulation.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"
#include "tools/python_env.hpp"

namespace yarnhom::tools {

namespace fs = std::filesystem;

namespace {

// What the renderer needs besides the frames: the colliders (drawn under the cloth).
void write_scene_info(const std::string& dir, const sim::Scene& s) {
  nlohmann::json j;
  j["name"] = s.name;
  j["colliders"] = nlohmann::json::array();
  for (const sim::Collider& c : s.colliders) {
    if (c.kind == sim::Collider::Kind::Sphere)
      j["colliders"].push_back({{"sphere", {{"center", {c.center.x(), c.center.y(), c.center.z()}}, {"radius", c.radius}}}});
    else
      j["colliders"].push_back({{"plane", {{"point", {c.center.x(), c.center.y(), c.center.z()}},
                                           {"normal", {c.normal.x(), c.normal.y(), c.normal.z()}}}}});
  }
  std::ofstream((fs::path(dir) / "scene_info.json").string()) << j.dump(1) << "\n";
}

// "mu 0.3" when every collider has the same coefficient, else the list; "none" without colliders.
std::string friction_description(const sim::Scene& s) {
  if (s.colliders.empty()) return "none (no collider)";
  std::string out;
  bool same = true;
  for (const sim::Collider& c : s.colliders) same = same && c.friction == s.colliders[0].friction;
  char buf[64];
  for (size_t k = 0; k < (same ? 1 : s.colliders.size()); ++k) {
    std::snprintf(buf, sizeof buf, "%s%g", k ? ", " : "mu ", s.colliders[k].friction);
    out += buf;
  }
  if (s.integrator == sim::Integrator::Linearized && out != "mu 0") out += " (not applied by the linearized integrator)";
  return out;
}

}  // namespace

void register_sim(CLI::App& app) {
  struct Opts {
    std::string scene, out, material, integrator, direction = "course", solver = "auto", render, hessian = "split";
    std::string size, stretch;
    double clamp = -1;
    double density = 0, dt = 0, tol = 0, alpha = -1, beta = -1, air = -1, friction = -1, eps_v = 0;
    int friction_updates = -1;
    int resolution = 0, frames = 0, substeps = 0, max_iterations = 0, threads = 0, blas_threads = 0;
    bool no_frames = false, profile = false, quiet = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "sim",
      "Simulate cloth with a baked material (thin shell, spec section 10; docs/sim.md). SCENE is a built-in "
      "scene -- drape (a 0.5 m sheet falling onto a sphere), hang (a sheet held by two corners), stretch (a strip "
      "clamped at both ends, 5 cm x 10 cm stretched quasi-statically to 170 % unless --size and --stretch say otherwise) -- or a scene file (JSON). "
      "Writes OUT/frames/frame_NNNN.obj, OUT/steps.csv (Newton iterations, energies, time per step), PNG "
      "renders in OUT/renders/ and, for stretch, OUT/stretch.csv and OUT/stretch.png (force per clamp width "
      "in N/m against stretch). Exit status 3 when the simulation becomes non-finite or a triangle leaves every "
      "physical strain (a material whose energy decreases outside its box).");
  cmd->add_option("SCENE", o->scene, "drape, hang, stretch, or a scene file (.json)")->required();
  cmd->add_option("-o,--output", o->out, "Output folder (created)")->required();
  cmd->add_option("--material", o->material,
                  "Baked file (yarnhom bake) or HYLC material JSON; required unless the scene file names one");
  cmd->add_option("--density", o->density,
                  "Areal density in kg/m^2 (default: the scene file's, else the material's; required for gravity "
                  "when neither has one)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--resolution", o->resolution,
                  "Built-in scenes: quads along the sheet's side (drape 40, hang 30) or across the strip (stretch 10)")
      ->check(CLI::Range(1, 2000));
  cmd->add_option("--direction", o->direction, "stretch: the strip's long axis, course (x) or wale (y)")
      ->check(CLI::IsMember({"course", "wale"}));
  cmd->add_option("--size", o->size,
                  "stretch: WIDTH,LENGTH of the strip in metres (default 0.05,0.10, the paper's); the default "
                  "resolution is then one quad per 5 mm across")
      ->check(non_empty());
  cmd->add_option("--stretch", o->stretch,
                  "stretch: load steps as 1.0:LAST:STEP, clamp separation / length (default 1.0:1.7:0.05); the strip "
                  "is always relaxed at 100 % first. Replaces --frames")
      ->check(non_empty());
  cmd->add_option("--clamp", o->clamp,
                  "stretch: clamp band at each short end in metres, every vertex within it held (default 0.005, "
                  "as yarnhom strip's --clamp; 0: the end rows only)")
      ->check(finite_non_negative());
  cmd->add_option("--integrator", o->integrator,
                  "newton (implicit Euler, Newton + line search; default), linearized (ARCSim-HYLC's one-solve "
                  "step), static (load steps to equilibrium; stretch's default)")
      ->check(CLI::IsMember({"newton", "linearized", "static"}));
  cmd->add_option("--dt", o->dt, "Seconds per frame (default 1/30)")->check(CLI::PositiveNumber);
  cmd->add_option("--substeps", o->substeps, "Time steps per frame (default 1)")->check(CLI::Range(1, 100000));
  cmd->add_option("--frames", o->frames, "Frames to simulate (or load steps for static runs)")->check(CLI::Range(1, 1000000));
  cmd->add_option("--tol", o->tol, "Newton tolerance: largest vertex move of a Newton step, m (default: 1e-2 l dt per step for "
                  "dynamics (IPC's velocity criterion), 1e-8 l for statics, l the sheet's rest diagonal; stretch 1e-9)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-iterations", o->max_iterations, "Newton iterations per step at most (default 100)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--rayleigh-alpha", o->alpha, "Mass-proportional damping, 1/s (default 0)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--rayleigh-beta", o->beta, "Stiffness-proportional damping, s (default 0)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--air", o->air, "Air drag on the normal velocity, kg/(m^2 s) (default 0)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--friction", o->friction,
                  "Coulomb friction coefficient mu between the cloth and every collider, overriding the scene's "
                  "(drape: 0.3; scene files: their \"friction\", else 0; 0 = frictionless). IPC's lagged smooth "
                  "friction: the normal force and tangent plane of each contact taken at the step's start; not "
                  "applied by --integrator linearized (docs/sim.md)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--friction-eps-v", o->eps_v,
                  "Friction's sticking velocity threshold eps_v, m/s: below it the friction force ramps smoothly "
                  "from 0 to mu lambda, so static friction is a creep slower than eps_v (default 1e-3 sheet "
                  "diagonals per second)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--friction-updates", o->friction_updates,
                  "Re-solves of each step with the normal forces and tangent planes taken at its solution "
                  "(IPC's lag updates; default 0: lagged at the step's start)")
      ->check(CLI::Range(0, 100));
  cmd->add_option("--solver", o->solver, "Sparse solver: auto (CHOLMOD when built with it), ldlt (Eigen), cholmod")
      ->check(CLI::IsMember({"auto", "ldlt", "cholmod"}));
  cmd->add_option("--hessian", o->hessian,
                  "PSD model of each element's Hessian for the Newton solves (and the linearized integrator's "
                  "stiffness): split (default: the material's 6x6 d2Psi/ds2 and the in-plane curvature term "
                  "projected, the bending curvature term left out; about 3x cheaper to assemble, as few Newton "
                  "iterations on the drapes measured) or projected (the exact 18x18 element Hessian projected onto "
                  "the PSD cone); docs/sim.md")
      ->check(CLI::IsMember({"projected", "split"}));
  cmd->add_option("--threads", o->threads, "Threads for the element loop (default: all cores)")->check(CLI::Range(1, 1024));
  cmd->add_option("--blas-threads", o->blas_threads,
                  "Threads of OpenBLAS inside CHOLMOD's factorization (default 1: on a machine of few shared cores "
                  "its spinning workers slow the element loop more than they speed the factorization; "
                  "docs/benchmarks.md). Ignored with the reference BLAS")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--render", o->render, "Frames to draw as PNG, e.g. 0,30,90, or none (default: the scene's)");
  cmd->add_flag("--no-frames", o->no_frames, "Do not write an OBJ per frame (timing runs)");
  cmd->add_flag("--profile", o->profile, "Time each step's parts (strain, material, chain rule, projection, assembly, solve)");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress line");
  cmd->callback([o] {
    using namespace yarnhom::sim;
    const bool file = o->scene.size() > 5 && o->scene.substr(o->scene.size() - 5) == ".json";
    if ((!o->size.empty() || !o->stretch.empty() || o->clamp >= 0) && o->scene != "stretch")
      throw std::invalid_argument("--size, --stretch and --clamp apply to the built-in stretch scene only");
    if (!o->stretch.empty() && o->frames > 0)
      throw std::invalid_argument("--stretch sets the load steps; give it or --frames, not both");
    StretchSize size;
    if (!o->size.empty()) {
      const std::vector<double> wl = parse_numbers(o->size, "--size");
      if (wl.size() != 2 || !(wl[0] > 0) || !(wl[1] > 0))
        throw std::invalid_argument("--size " + o->size + ": expected WIDTH,LENGTH in metres, both positive");
      size.width = wl[0];
      size.length = wl[1];
    }
    if (!o->stretch.empty()) {
      const std::vector<double> r = parse_stretch_range(o->stretch);
      if (std::abs(r.front() - 1.0) > 1e-9 || r.size() < 2)
        throw std::invalid_argument("--stretch " + o->stretch + ": give 1.0:LAST:STEP with LAST > 1 (the strip starts at 100 %)");
      size.last = r.back();
      size.steps = int(r.size()) - 1;
    }
    if (o->clamp >= 0) size.clamp = o->clamp;
    Scene s = file ? read_scene_json(o->scene)
                   : builtin_scene(o->scene, o->resolution, o->direction == "wale" ? 'y' : 'x', size);
    if (file && o->resolution) throw std::invalid_argument("--resolution applies to the built-in scenes only");
    if (!o->integrator.empty()) s.integrator = parse_integrator(o->integrator);
    if (o->dt > 0) s.dt = o->dt;
    if (o->substeps > 0) s.substeps = o->substeps;
    if (o->frames > 0) s.frames = o->frames;
    if (o->tol > 0) s.newton.tol_step = o->tol;
    if (o->max_iterations > 0) s.newton.max_iterations = o->max_iterations;
    if (o->alpha >= 0) s.rayleigh_alpha = o->alpha;
    if (o->beta >= 0) s.rayleigh_beta = o->beta;
    if (o->air >= 0) s.air_drag = o->air;
    if (o->friction >= 0)
      for (Collider& c : s.colliders) c.friction = o->friction;
    if (o->eps_v > 0) s.friction_eps_v = o->eps_v;
    if (o->friction_updates >= 0) s.friction_updates = o->friction_updates;
    if (!o->render.empty()) {
      s.render_frames.clear();
      if (o->render != "none")
        for (double f : parse_numbers(o->render, "--render")) {
          if (f != int(f) || f < 0) throw std::invalid_argument("--render: frame numbers must be integers >= 0");
          s.render_frames.push_back(int(f));
        }
    }
    const std::string mpath = o->material.empty() ? s.material : o->material;
    if (mpath.empty()) throw std::invalid_argument("no material: give --material BAKED.h5 (or a HYLC material JSON)");
    const LoadedMaterial mat = load_material(mpath);
    // Density: the command line, then the scene file, then the material.
    double rho = 0;
    std::string rho_from;
    if (o->density > 0) {
      rho = o->density;
      rho_from = "--density";
    } else if (s.areal_density) {
      rho = *s.areal_density;
      rho_from = "the scene file";
    } else if (mat.areal_density) {
      rho = *mat.areal_density;
      rho_from = mpath;
    }
    const bool needs_mass = s.integrator != Integrator::Static || s.gravity.norm() > 0;
    if (needs_mass && !(rho > 0))
      throw std::invalid_argument(mpath + " carries no areal density (a baked file gets the attribute areal_density from "
                                  "its dataset; older files have none): give --density KG_PER_M2, e.g. --density 0.3");
    if (o->threads > 0) omp_set_num_threads(o->threads);
    set_blas_threads(o->blas_threads > 0 ? o->blas_threads : 1);
    retain_freed_memory();  // every Newton iteration reallocates the same large arrays (core/heap_policy.hpp)
    SimSettings set;
    set.out_dir = o->out;
    set.solver = parse_solver_kind(o->solver);
    set.hessian = parse_hessian_model(o->hessian);
    set.profile = o->profile;
    set.write_frames = !o->no_frames;
    fs::create_directories(o->out);
    write_scene_info(o->out, s);
    const int threads = o->threads > 0 ? o->threads : omp_get_max_threads();
    std::fprintf(stderr,
                 "sim %s: %d triangles, %d vertices; material %s (%s)%s; density %g kg/m^2%s; %s, dt %g s x %d "
                 "substep(s), %d %s; friction %s; %d thread(s); %s\n",
                 s.name.c_str(), s.mesh.num_triangles(), s.mesh.num_vertices(), mpath.c_str(), mat.kind.c_str(),
                 mat.missing_terms.empty() ? "" : (", absent terms count as 0: " + mat.missing_terms).c_str(), rho,
                 rho_from.empty() ? "" : (" (from " + rho_from + ")").c_str(), integrator_name(s.integrator), s.dt,
                 s.substeps, s.frames, s.integrator == Integrator::Static ? "load steps" : "frames",
                 friction_description(s).c_str(), threads,
                 blas_description());
    const auto start = std::chrono::steady_clock::now();
    const bool tty = stderr_is_tty();
    int last_line = -1;
    auto progress = [&](int frame, const SimResult& r) {
      if (o->quiet) return;
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double eta = el / frame * (s.frames - frame);
      double its = 0;
      for (const StepRecord& st : r.steps) its += st.iterations;
      const double per = r.steps.empty() ? 0 : 1e3 * el / r.steps.size();
      const int pct = 100 * frame / s.frames;
      if (!tty && pct / 10 == last_line && frame != s.frames) return;
      last_line = pct / 10;
      std::fprintf(stderr, "%sframe %d/%d  %.1f Newton it/step  %.0f ms/step  elapsed %s  ETA %s%s", tty ? "\r" : "", frame,
                   s.frames, r.steps.empty() ? 0.0 : its / r.steps.size(), per, format_seconds(el).c_str(),
                   format_seconds(eta).c_str(), tty ? "   " : "\n");
    };
    const SimResult r = run_simulation(s, mat.fn, rho, set, progress);
    if (tty && !o->quiet) std::fprintf(stderr, "\n");
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double its = 0, wall = 0;
    int unconverged = 0;
    StepRecord sum;
    for (const StepRecord& st : r.steps) {
      its += st.iterations;
      wall += st.wall;
      unconverged += !st.converged;
      sum.t_strain += st.t_strain;
      sum.t_material += st.t_material;
      sum.t_chain += st.t_chain;
      sum.t_project += st.t_project;
      sum.t_scatter += st.t_scatter;
      sum.t_assemble += st.t_assemble;
      sum.t_solve += st.t_solve;
      sum.t_line_search += st.t_line_search;
      sum.projected += st.projected;
      sum.elements += st.elements;
    }
    const double n = std::max<size_t>(1, r.steps.size());
    std::fprintf(stderr, "sim %s: %d/%d frames, %zu steps, %.2f Newton iterations/step, %.1f ms/step, %s total%s\n",
                 s.name.c_str(), r.frames_done, s.frames, r.steps.size(), its / n, 1e3 * wall / n,
                 format_seconds(el).c_str(), unconverged ? (", " + std::to_string(unconverged) + " step(s) not converged to --tol").c_str() : "");
    if (o->profile)
      std::fprintf(stderr,
                   "profile (ms per step): assembly %.2f wall [element loop CPU: strain %.2f, material %.2f, chain rule "
                   "%.2f, PSD projection %.2f (%.1f %% of elements), scatter %.2f], solve %.2f, line search %.2f; "
                   "solver %s\n",
                   1e3 * sum.t_assemble / n, 1e3 * sum.t_strain / n, 1e3 * sum.t_material / n, 1e3 * sum.t_chain / n,
                   1e3 * sum.t_project / n, sum.elements ? 100.0 * sum.projected / sum.elements : 0.0, 1e3 * sum.t_scatter / n,
                   1e3 * sum.t_solve / n, 1e3 * sum.t_line_search / n, LinearSolver(set.solver).name());
    if (!r.stretch.empty()) {
      std::fprintf(stderr, "stretch   N/m (clamp)   dPsi/ds at the middle\n");
      for (const StretchRow& row : r.stretch)
        std::fprintf(stderr, "%6.0f %%  %12.5g  %12.5g\n", 100 * row.stretch, row.force_per_width, row.middle_dpsi);
    }
    // Pictures.
    if (!s.render_frames.empty() || !r.stretch.empty()) {
      const std::string py = find_python("matplotlib, numpy");
      const std::string script = (fs::path(scripts_dir()) / "plot" / "render_sim.py").string();
      if (py.empty()) {
        std::fprintf(stderr, "sim: no python3 with matplotlib and numpy (tried $YARNHOM_PYTHON, /usr/bin/python3, python3): "
                             "no PNG written; install python3-matplotlib or set YARNHOM_PYTHON\n");
      } else if (!fs::exists(script)) {
        std::fprintf(stderr, "sim: %s not found (set YARNHOM_SCRIPTS to the tools folder): no PNG written\n", script.c_str());
      } else {
        std::string frames;
        for (int f : s.render_frames)
          if (f <= r.frames_done) frames += (frames.empty() ? "" : ",") + std::to_string(f);
        const std::string cmdline = "'" + py + "' '" + script + "' '" + o->out + "'" +
                                    (frames.empty() || o->no_frames ? "" : " --frames " + frames);
        if (std::system(cmdline.c_str()) != 0) std::fprintf(stderr, "sim: the render script failed (%s)\n", cmdline.c_str());
      }
    }
    if (!r.diverged.empty()) {
      std::fprintf(stderr, "sim %s: stopped at step %zu (frame %d): %s\n", s.name.c_str(), r.steps.size(),
                   r.frames_done + 1, r.diverged.c_str());
      throw ExitCode{3};
    }
    if (!r.finite) {
      std::fprintf(stderr, "sim %s: the simulation became non-finite at step %zu (frame %d)\n", s.name.c_str(),
                   r.steps.size(), r.frames_done + 1);
      throw ExitCode{3};
    }
  });
}

}  // namespace yarnhom::tools
