#include "sim/sim_run.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <memory>
#include <stdexcept>
#include <vector>

#include "core/scope_profile.hpp"
#include "core/console.hpp"
#include "core/file_checks.hpp"
#include "core/heap_policy.hpp"
#include "core/number_list.hpp"
#include "material/material_source.hpp"
#include "numerics/blas_threads.hpp"
#ifdef YARNHOM_SIM_CUDA
#include "cuda/api.hpp"
#include "cuda/block_jacobi_pcg.hpp"
#endif
#include "sim/garment.hpp"
#include "sim/hessian_model.hpp"
#include "sim/obj_io.hpp"
#include "sim/scene_json.hpp"

namespace yarnhom::sim {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// What the renderer needs besides the frames: the colliders (drawn under the cloth) and where
// the moving ones are at each frame: frame k's time is k frame_time (0 for a static run, whose
// obstacles stay where they are at t = 0), a capsule moves along its path, a mesh collider
// interpolates its OBJ frames (named by absolute path, with the scale and offset applied).
void write_scene_info(const std::string& dir, const Scene& s) {
  using nlohmann::json;
  auto v3 = [](const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); };
  json j;
  j["name"] = s.name;
  j["frame_time"] = s.integrator == Integrator::Static ? 0.0 : s.dt;
  j["colliders"] = json::array();
  for (const Collider& c : s.colliders) {
    if (c.kind == Collider::Kind::Sphere)
      j["colliders"].push_back({{"sphere", {{"center", v3(c.center)}, {"radius", c.radius}}}});
    else
      j["colliders"].push_back({{"plane", {{"point", v3(c.center)}, {"normal", v3(c.normal)}}}});
  }
  for (const CapsuleObstacle& c : s.obstacles.capsules) {
    json cap = {{"a", v3(c.a)}, {"b", v3(c.b)}, {"radius", c.radius}, {"moving", !c.path.empty()}};
    if (!c.path.empty()) cap["path"] = c.path;
    j["colliders"].push_back({{"capsule", cap}});
  }
  for (const MeshObstacle& m : s.obstacles.meshes) {
    json mesh = {{"frame_dt", m.frame_dt}};
    if (!m.files.empty()) {  // read from OBJ files: name them (the frames of a walk would fill megabytes)
      mesh["frames"] = m.files;
      mesh["scale"] = m.scale;
      mesh["translate"] = v3(m.offset);
    } else {  // made in code: the triangles themselves
      json frames = json::array();
      for (const Eigen::MatrixX3d& x : m.frames) {
        json f = json::array();
        for (int v = 0; v < x.rows(); ++v) f.push_back(v3(x.row(v).transpose()));
        frames.push_back(f);
      }
      json tris = json::array();
      for (int t = 0; t < m.tris.rows(); ++t) tris.push_back({m.tris(t, 0), m.tris(t, 1), m.tris(t, 2)});
      mesh["vertices"] = frames;
      mesh["triangles"] = tris;
    }
    j["colliders"].push_back({{"mesh", mesh}});
  }
  std::ofstream((fs::path(dir) / "scene_info.json").string()) << j.dump(1) << "\n";
}

// "mu 0.3" when every collider has the same coefficient, else the list; "none" without colliders;
// then the capsules, meshes and self-collision (sim/contact.hpp).
std::string contact_description(const Scene& s) {
  const bool bw = s.integrator == Integrator::BaraffWitkin;
  char buf[160];
  std::snprintf(buf, sizeof buf, "; self-collision %s", bw || !s.self_collision ? "off" : "on");
  std::string out = buf;
  if (s.self_collision && !bw) {
    std::snprintf(buf, sizeof buf, " (mu %g, dhat %g m)", std::max(0.0, s.self_friction), s.dhat);
    out += buf;
  }
  if (!s.obstacles.empty()) {
    std::snprintf(buf, sizeof buf, "; %zu capsule(s), %zu mesh collider(s)", s.obstacles.capsules.size(),
                  s.obstacles.meshes.size());
    out += buf;
  }
  return out;
}

std::string friction_description(const Scene& s) {
  if (s.colliders.empty()) return "none (no collider)" + contact_description(s);
  std::string out;
  bool same = true;
  for (const Collider& c : s.colliders) same = same && c.friction == s.colliders[0].friction;
  char buf[64];
  for (size_t k = 0; k < (same ? 1 : s.colliders.size()); ++k) {
    std::snprintf(buf, sizeof buf, "%s%g", k ? ", " : "mu ", s.colliders[k].friction);
    out += buf;
  }
  if (s.integrator == Integrator::BaraffWitkin && out != "mu 0") out += " (not applied by the Baraff-Witkin integrator)";
  return out + contact_description(s);
}

// The built-in stretch scene's --size, --stretch and --clamp.
StretchSize stretch_size(const SimRunOptions& o) {
  StretchSize size;
  if (!o.size.empty()) {
    const std::vector<double> wl = parse_numbers(o.size, "--size");
    if (wl.size() != 2 || !(wl[0] > 0) || !(wl[1] > 0))
      throw std::invalid_argument("--size " + o.size + ": expected WIDTH,LENGTH in metres, both positive");
    size.width = wl[0];
    size.length = wl[1];
    // The strip's quads (sim/scene.cpp: --resolution, else one per 5 mm, across; square along),
    // bounded before the mesh is allocated (--size 1e9,1e9 ran out of memory).
    const double across = o.resolution > 0 ? o.resolution : std::max(2.0, std::round(wl[0] / 0.005));
    const double quads = across * std::max(1.0, std::round(across * wl[1] / wl[0]));
    if (!(quads <= 4e6)) {
      char buf[300];
      std::snprintf(buf, sizeof buf, "--size %s: the strip would have %.3g quads (%.3g across, square along); at most 4e6 "
                    "(a quad per 5 mm across, or --resolution)", o.size.c_str(), quads, across);
      throw std::invalid_argument(buf);
    }
  }
  if (!o.stretch.empty()) {
    const std::vector<double> r = parse_stretch_range(o.stretch);
    if (std::abs(r.front() - 1.0) > 1e-9 || r.size() < 2)
      throw std::invalid_argument("--stretch " + o.stretch + ": give 1.0:LAST:STEP with LAST > 1 (the strip starts at 100 %)");
    size.last = r.back();
    size.steps = int(r.size()) - 1;
  }
  if (o.clamp >= 0) {
    // Named here, with the length it must fit in (sim/scene.cpp's check names neither).
    if (!(o.clamp < size.length / 2)) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "--clamp %g: the clamp band must be shorter than half the strip's length (%g m%s)",
                    o.clamp, size.length, o.size.empty() ? ", the default; --size WIDTH,LENGTH" : ": --size");
      throw std::invalid_argument(buf);
    }
    size.clamp = o.clamp;
  }
  return size;
}

// `sim tshirt --body FILE.obj`: the body OBJ instead of the mannequin (friction 0.3, as its).
void wear_body(const std::string& scene, const std::string& body, Scene& s) {
  if (scene != "tshirt")
    throw std::invalid_argument("--body applies to the built-in tshirt scene only (a scene file names its body in \"colliders\")");
  MeshObstacle b;
  try {
    b = read_mesh_obstacle({body}, 1.0 / 30);
    check_body_clear_of_tshirt(b);
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("--body: ") + e.what());
  }
  b.friction = 0.3;
  s.obstacles.capsules.clear();
  s.obstacles.meshes = {std::move(b)};
}

// The scene with the command line's overrides.
Scene make_scene(const SimRunOptions& o) {
  const bool file = o.scene.size() > 5 && o.scene.substr(o.scene.size() - 5) == ".json";
  if ((!o.size.empty() || !o.stretch.empty() || o.clamp >= 0) && o.scene != "stretch")
    throw std::invalid_argument("--size, --stretch and --clamp apply to the built-in stretch scene only");
  if (!o.stretch.empty() && o.frames > 0)
    throw std::invalid_argument("--stretch sets the load steps; give it or --frames, not both");
  const StretchSize size = stretch_size(o);
  Scene s = file ? read_scene_json(o.scene) : builtin_scene(o.scene, o.resolution, o.direction == "wale" ? 'y' : 'x', size);
  if (file && o.resolution) throw std::invalid_argument("--resolution applies to the built-in scenes only");
  if (!o.body.empty()) wear_body(o.scene, o.body, s);
  if (!o.integrator.empty()) s.integrator = parse_integrator(o.integrator);
  if (o.dt > 0) s.dt = o.dt;
  if (o.substeps > 0) s.substeps = o.substeps;
  if (o.frames > 0) s.frames = o.frames;
  if (o.tol > 0) s.newton.tol_step = o.tol;
  if (!o.tol_norm.empty()) s.newton.norm = parse_step_norm(o.tol_norm);
  if (o.max_iterations > 0) s.newton.max_iterations = o.max_iterations;
  if (o.factor_reuse >= 0) s.newton.reuse_cg = o.factor_reuse;
  if (o.factor_reuse_tol > 0) s.newton.reuse_tol = o.factor_reuse_tol;
  if (o.alpha >= 0) s.rayleigh_alpha = o.alpha;
  if (o.beta >= 0) s.rayleigh_beta = o.beta;
  if (o.air >= 0) s.air_drag = o.air;
  if (o.friction >= 0) {
    for (Collider& c : s.colliders) c.friction = o.friction;
    for (CapsuleObstacle& c : s.obstacles.capsules) c.friction = o.friction;
    for (MeshObstacle& m : s.obstacles.meshes) m.friction = o.friction;
  }
  if (!o.self_collision.empty()) {
    if (o.self_collision != "on" && o.self_collision != "off")
      throw std::invalid_argument("--self-collision: expected on or off, not '" + o.self_collision + "'");
    s.self_collision = o.self_collision == "on";
  }
  if (o.dhat > 0) s.dhat = o.dhat;
  if (o.eps_v > 0) s.friction_eps_v = o.eps_v;
  if (o.friction_updates >= 0) s.friction_updates = o.friction_updates;
  if (!o.render.empty()) {
    s.render_frames.clear();
    if (o.render != "none")
      for (double f : parse_numbers(o.render, "--render")) {
        if (f != int(f) || f < 0) throw std::invalid_argument("--render: frame numbers must be integers >= 0");
        s.render_frames.push_back(int(f));
      }
  }
  return s;
}

// Density: the command line, then the scene file, then the material; refused where the run
// needs a mass and there is none.
double areal_density(const SimRunOptions& o, const Scene& s, const LoadedMaterial& mat, const std::string& mpath,
                     std::string& from) {
  double rho = 0;
  if (o.density > 0) {
    rho = o.density;
    from = "--density";
  } else if (s.areal_density) {
    rho = *s.areal_density;
    from = "the scene file";
  } else if (mat.areal_density) {
    rho = *mat.areal_density;
    from = mpath;
  }
  const bool needs_mass = s.integrator != Integrator::Static || s.gravity.norm() > 0;
  if (needs_mass && !(rho > 0))
    throw std::invalid_argument(mpath + " carries no areal density (a baked file gets the attribute areal_density from "
                                "its dataset; older files have none): give --density KG_PER_M2, e.g. --density 0.3");
  return rho;
}

// The progress line: redrawn in place on a terminal, else one line per tenth of the run.
FrameCallback progress_line(const SimRunOptions& o, const Scene& s, Clock::time_point start) {
  const bool tty = stderr_is_tty();
  auto last_line = std::make_shared<int>(-1);
  auto checked = std::make_shared<size_t>(0);  // steps already looked at for the iteration cap
  auto reported = std::make_shared<int>(0);
  auto ends = std::make_shared<std::vector<double>>();  // elapsed at the end of each frame
  const bool quiet = o.quiet;
  const int frames = s.frames, cap = s.newton.max_iterations;
  const std::string name = s.name;
  return [=](int frame, const SimResult& r) {
    if (quiet) return;
    // A step that ended unconverged (at the Newton iteration cap, or with no descent left) is
    // reported at once, one line, as well as in the summary.
    for (; *checked < r.steps.size(); ++*checked) {
      const StepRecord& st = r.steps[*checked];
      if (st.converged || ++*reported > 10) continue;
      std::fprintf(stderr, "%ssim %s: step %d (frame %d) not converged to --tol after %d Newton iteration(s)%s; going on%s\n",
                   tty && *last_line >= 0 ? "\n" : "", name.c_str(), st.step, st.frame, st.iterations,
                   st.iterations >= cap ? " (the cap, --max-iterations)" : "",
                   *reported == 10 ? " (further ones are counted in the summary only)" : "");
    }
    const double el = std::chrono::duration<double>(Clock::now() - start).count();
    // The ETA at the pace of the last 5 frames, the first left out (it carries the set-up:
    // symbolic factorization; a drape's first frame made the old whole-run mean say 18 min for a
    // run of 2 min 39 s): a drape's frames get cheaper as the cloth comes to rest (23 Newton
    // iterations in the first step, 3 at the end). None yet after the first frame.
    ends->push_back(el);
    const size_t n = ends->size(), back = std::min<size_t>(5, n - 1);
    const double eta = back > 0 ? (el - (*ends)[n - 1 - back]) / double(back) * (frames - frame) : 0.0;
    double its = 0;
    for (const StepRecord& st : r.steps) its += st.iterations;
    const double per = r.steps.empty() ? 0 : 1e3 * el / r.steps.size();
    const int pct = 100 * frame / frames;
    if (!tty && pct / 10 == *last_line && frame != frames) return;
    *last_line = pct / 10;
    std::fprintf(stderr, "%sframe %d/%d  %.1f Newton it/step  %.0f ms/step  elapsed %s  ETA %s at the current pace%s", tty ? "\r" : "", frame,
                 frames, r.steps.empty() ? 0.0 : its / r.steps.size(), per, format_seconds(el).c_str(),
                 frame > 1 || frames == 1 ? format_seconds(eta).c_str() : "?", tty ? "   " : "\n");
  };
}

void print_summary(const SimRunOptions& o, const Scene& s, const SimSettings& set, const SimResult& r, double el) {
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
    sum.factorizations += st.factorizations;
    sum.cg_iterations += st.cg_iterations;
    sum.evaluations += st.evaluations;
    sum.elements += st.elements;
  }
  const double n = std::max<size_t>(1, r.steps.size());
  std::fprintf(stderr, "sim %s: %d/%d frames, %zu steps, %.2f Newton iterations/step, %.1f ms/step, %s total%s\n",
               s.name.c_str(), r.frames_done, s.frames, r.steps.size(), its / n, 1e3 * wall / n,
               format_seconds(el).c_str(),
               unconverged ? (", " + std::to_string(unconverged) + " step(s) not converged to --tol").c_str() : "");
  if (r.residual_vertices > 0)
    std::fprintf(stderr,
                 "sim %s: residual force of the last frame, |f|/(m g) over the %d free vertices off the colliders: rms "
                 "%.3g, max %.3g\n",
                 s.name.c_str(), r.residual_vertices, r.residual_rms, r.residual_max);
  if (o.profile)
    std::fprintf(stderr,
                 "profile (ms per step): assembly %.2f wall [element loop CPU: strain %.2f, material %.2f, chain rule "
                 "%.2f, PSD projection %.2f (%.1f %% of elements), scatter %.2f], solve %.2f, line search %.2f, rest of "
                 "the step (its start, CCD) %.2f; solver %s, %d pattern analyses; per step %.2f factorizations, %.2f CG "
                 "iterations on a reused factor, %.2f line-search energies\n",
                 1e3 * sum.t_assemble / n, 1e3 * sum.t_strain / n, 1e3 * sum.t_material / n, 1e3 * sum.t_chain / n,
                 1e3 * sum.t_project / n, sum.elements ? 100.0 * sum.projected / sum.elements : 0.0,
                 1e3 * sum.t_scatter / n, 1e3 * sum.t_solve / n, 1e3 * sum.t_line_search / n,
                 1e3 * (wall - sum.t_assemble - sum.t_solve - sum.t_line_search) / n,
                 r.solver_name.c_str(), r.analyses, sum.factorizations / n,
                 sum.cg_iterations / n, sum.evaluations / n);
  if (o.profile) {
    // The named parts (core/scope_profile.hpp): wall time on the stepping thread, each part
    // including the parts nested in it.
    std::fprintf(stderr, "profile parts (ms per step, wall, nested parts included; calls per step):\n");
    for (const prof::Entry& e : prof::entries())
      std::fprintf(stderr, "  %8.2f  %6.2f  %s\n", 1e3 * e.seconds / n, double(e.calls) / n, e.name.c_str());
  }
  if (r.solver_solves > 0)
    std::fprintf(stderr, "sim %s: %s, %.1f CG iterations per solve (relative residual %.1e)\n", s.name.c_str(),
                 r.solver_name.c_str(), double(r.solver_iterations) / r.solver_solves, set.pcg_tolerance);
  if (!r.stretch.empty()) {
    std::fprintf(stderr, "stretch   N/m (clamp)   dPsi/ds at the middle\n");
    for (const StretchRow& row : r.stretch)
      std::fprintf(stderr, "%6.0f %%  %12.5g  %12.5g\n", 100 * row.stretch, row.force_per_width, row.middle_dpsi);
  }
}

// The output folder, once the inputs are read: created, its temporaries of killed runs removed,
// its files checked (no FIFO, device or input among them), and what an earlier run wrote there
// removed, saying so in one line: its frames, renders and force curve (a shorter rerun left
// frame_0005..0012.obj beside the new steps.csv). Only the names sim writes are touched.
void prepare_sim_folder(const SimRunOptions& o, const Scene& s, const std::string& mpath) {
  std::vector<std::string> inputs = {mpath};
  if (fs::is_regular_file(o.scene)) inputs.push_back(o.scene);
  prepare_output_folder(o.out, {"frames"}, {"steps.csv", "stretch.csv", "scene_info.json", "rest.obj", "sim.mp4"}, inputs);
  if (fs::is_directory(fs::path(o.out) / "renders")) remove_stale_temporaries_in((fs::path(o.out) / "renders").string());
  auto numbered = [](const fs::path& f, const char* ext) {
    const std::string n = f.filename().string(), e = ext;
    if (n.size() <= 6 + e.size() || n.compare(0, 6, "frame_") != 0 || n.compare(n.size() - e.size(), e.size(), e) != 0)
      return -1;
    const std::string digits = n.substr(6, n.size() - 6 - e.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
    return std::stoi(digits);
  };
  int frames = 0, beyond = 0, renders = 0;
  std::vector<std::string> files;
  std::error_code ec;
  for (const char* sub : {"frames", "renders"}) {
    const bool obj = std::string(sub) == "frames";
    for (const auto& e : fs::directory_iterator(fs::path(o.out) / sub, ec)) {
      const int k = numbered(e.path(), obj ? ".obj" : ".png");
      if (k < 0 || !e.is_regular_file() || !fs::remove(e.path(), ec)) continue;
      (obj ? frames : renders)++;
      if (obj && (o.no_frames || k > s.frames)) ++beyond;
    }
  }
  for (const char* f : {"stretch.csv", "stretch.png", "steps.csv", "scene_info.json", "rest.obj", "sim.mp4"})
    if (fs::is_regular_file(fs::path(o.out) / f) && fs::remove(fs::path(o.out) / f, ec) && std::string(f).find("stretch") == 0)
      files.push_back(f);
  if (frames + renders == 0 && files.empty()) return;
  std::string what = std::to_string(frames) + " frame OBJ(s)";
  if (beyond) what += " (" + std::to_string(beyond) + (o.no_frames ? " with --no-frames" : " beyond this run's " + std::to_string(s.frames)) + ")";
  if (renders) what += ", " + std::to_string(renders) + " render(s)";
  for (const std::string& f : files) what += ", " + f;
  std::fprintf(stderr, "sim: %s held an earlier run's outputs: removed %s\n", o.out.c_str(), what.c_str());
}

}  // namespace

void check_sim_options(const SimRunOptions& o) {
  if (!o.material.empty()) check_input_file(o.material, "--material");
  make_scene(o);
}

SimRunOutcome run_sim(const SimRunOptions& o) {
  check_output_folder(o.out);  // before any work: a file, a FIFO, /dev/null, /proc/... (created below)
  const Scene s = make_scene(o);
  const std::string mpath = o.material.empty() ? s.material : o.material;
  if (mpath.empty()) throw std::invalid_argument("no material: give --material BAKED.h5 (or a HYLC material JSON)");
  const LoadedMaterial mat = load_material(mpath);
  std::string rho_from;
  const double rho = areal_density(o, s, mat, mpath, rho_from);
  if (o.threads > 0) omp_set_num_threads(o.threads);
  numerics::set_blas_threads(o.blas_threads > 0 ? o.blas_threads : 1);
  retain_freed_memory();  // every Newton iteration reallocates the same large arrays (core/heap_policy.hpp)
  SimSettings set;
  set.out_dir = o.out;
  set.material_value = mat.value;
#ifdef YARNHOM_SIM_CUDA
  numerics::register_pcg_device(&cuda::make_pcg_device);  // --solver pcg-cuda
#endif
  bool gpu_usable = false;
#ifdef YARNHOM_SIM_CUDA
  gpu_usable = o.solver == "auto" && cuda::device_count() > 0;
#endif
  set.solver = resolve_auto_solver(parse_solver_kind(o.solver), s, gpu_usable);
  set.pcg_tolerance = o.pcg_tolerance;
  set.hessian = parse_hessian_model(o.hessian);
  set.eigen_filter = o.eigen_filter == "clamp" ? numerics::EigenFilter::Clamp : numerics::EigenFilter::Abs;
  set.profile = o.profile;
  prof::reset();
  prof::set_enabled(o.profile);
  set.write_frames = !o.no_frames;
  prepare_sim_folder(o, s, mpath);
  write_scene_info(o.out, s);
  if (!o.no_frames) write_rest_obj((fs::path(o.out) / "rest.obj").string(), s.mesh);  // the frames' uv are in [0, 1]
  const int threads = o.threads > 0 ? o.threads : omp_get_max_threads();
  // The linear solver, and why when `auto` chose the GPU's CG.
  const std::string solver = std::string(numerics::solver_kind_name(set.solver)) +
                             (o.solver == "auto" && set.solver == SolverKind::PcgCuda ? " (auto: a GPU is there)" : "");
  std::fprintf(stderr,
               "sim %s: %d triangles, %d vertices; material %s (%s)%s; density %g kg/m^2%s; %s, dt %g s x %d "
               "substep(s), %d %s; friction %s; solver %s; %d thread(s); %s\n",
               s.name.c_str(), s.mesh.num_triangles(), s.mesh.num_vertices(), mpath.c_str(), mat.kind.c_str(),
               mat.missing_terms.empty() ? "" : (", absent terms count as 0: " + mat.missing_terms).c_str(), rho,
               rho_from.empty() ? "" : (" (from " + rho_from + ")").c_str(), integrator_name(s.integrator), s.dt,
               s.substeps, s.frames, s.integrator == Integrator::Static ? "load steps" : "frames",
               friction_description(s).c_str(), solver.c_str(), threads, numerics::blas_description());
  if (mat.guard && !o.quiet) std::fprintf(stderr, "sim %s: %s\n", s.name.c_str(), describe(*mat.guard).c_str());
  const auto start = Clock::now();
  // What the simulation refuses at its start (a vertex inside a collider, a collider's friction)
  // comes from the scene: the message names it (it named neither the scene file nor the key).
  auto simulate = [&] {
    try {
      return run_simulation(s, mat.fn, rho, set, progress_line(o, s, start));
    } catch (const std::invalid_argument& e) {
      const bool file = o.scene.size() > 5 && o.scene.substr(o.scene.size() - 5) == ".json";
      std::string what = e.what();
      const size_t at = what.find("inside collider ");
      if (at != std::string::npos)
        what += " (" + std::string(file ? "the scene's colliders[" : "the built-in scene's collider ") + what.substr(at + 16) +
                (file ? "]" : "") + "; every vertex must start outside every collider)";
      throw std::invalid_argument((file ? o.scene : "sim " + o.scene) + ": " + what);
    }
  };
  SimRunOutcome out{s.name, s.render_frames, simulate()};
  if (stderr_is_tty() && !o.quiet) std::fprintf(stderr, "\n");
  print_summary(o, s, set, out.result, std::chrono::duration<double>(Clock::now() - start).count());
  return out;
}

int sim_exit_status(const SimRunOutcome& r) {
  if (!r.result.diverged.empty()) {
    std::fprintf(stderr, "sim %s: stopped at step %zu (frame %d): %s\n", r.scene.c_str(), r.result.steps.size(),
                 r.result.frames_done + 1, r.result.diverged.c_str());
    return 3;
  }
  if (!r.result.finite) {
    std::fprintf(stderr, "sim %s: the simulation became non-finite at step %zu (frame %d)\n", r.scene.c_str(),
                 r.result.steps.size(), r.result.frames_done + 1);
    return 3;
  }
  return 0;
}

}  // namespace yarnhom::sim
