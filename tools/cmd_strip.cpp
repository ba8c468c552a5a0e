// yarnhom strip PATTERN -o DIR: a yarn-level fabric strip tiled from a periodic pattern, joined
// into one yarn, clamped at its short ends and stretched quasi-statically (docs/strip.md;
// supplement section 4.2). Resumable per load step.
//
// DIR/settings.txt   what the run is (a rerun with other settings is refused)
// DIR/strip.obj      the generated strip's centrelines (OBJ polylines, m)
// DIR/steps/step_KKK.h5        the equilibrium of load step K (what a resumed run continues from)
// DIR/centrelines/step_KKK.obj its centrelines
// DIR/force.csv      per load step: stretch, force per nominal width (N/m), both clamps' forces,
//                    energy and its parts, iterations, times, closest pair, topology certificate,
//                    and last the force per load width (yarn::Strip::load_width; what accuracy uses)
// DIR/strip.png, deformed.png, force.png (when a python3 with matplotlib is found)
#include <omp.h>

#include <chrono>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "core/blas_threads.hpp"
#include "core/heap_policy.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/file_checks.hpp"
#include "tools/child_process.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"
#include "tools/python_env.hpp"
#include "yarn/generate.hpp"
#include "yarn/strip_generate.hpp"
#include "yarn/strip_io.hpp"

namespace yarnhom::tools {
namespace {

namespace fs = std::filesystem;

struct StripOpts {
  std::string pattern, out, size = "0.05,0.10", direction = "course", stretch = "1.0:1.7:0.05", material;
  std::string newton = "trust-region";
  double clamp = 0.005, connector_scale = 1.0 / 200, tolerance = 1e-10, rest_time_limit = 300;
  int max_iterations = 300, threads = 0;
  bool no_bind_off = false, restart = false, no_plots = false, verbose = false;
};

yarn::Pattern load_pattern(const std::string& what) {
  if (fs::exists(what)) {
    check_input_file(what, "PATTERN");  // a regular file (a FIFO would block the reader)
    return yarn::read_pyp(what);
  }
  if (yarn::is_builtin_pattern(what)) return yarn::builtin_pattern(what);
  std::string names;
  for (const auto& n : yarn::builtin_pattern_names()) names += (names.empty() ? "" : ", ") + n;
  throw std::invalid_argument("pattern '" + what + "' is neither a file nor a built-in pattern (" + names + ")");
}

// "a:b:c" -> 1.0 (always relaxed first), then a, a + c, ... up to b (inclusive), above 1.
std::vector<double> parse_stretches(const std::string& text) {
  const auto c1 = text.find(':'), c2 = text.rfind(':');
  if (c1 == std::string::npos || c1 == c2)
    throw std::invalid_argument("--stretch: expected FROM:TO:STEP (e.g. 1.0:1.7:0.05), got '" + text + "'");
  const double a = parse_numbers(text.substr(0, c1), "--stretch")[0];
  const double b = parse_numbers(text.substr(c1 + 1, c2 - c1 - 1), "--stretch")[0];
  const double d = parse_numbers(text.substr(c2 + 1), "--stretch")[0];
  if (!(a >= 1.0 && b >= a && b <= 10.0 && d > 0))
    throw std::invalid_argument("--stretch: need 1 <= FROM <= TO <= 10 and STEP > 0 (stretch 1 = as generated), got '" +
                                text + "'");
  std::vector<double> s = {1.0};
  for (int k = 0;; ++k) {
    const double v = a + k * d;
    if (v > b + 1e-9 * d) break;
    if (v > 1.0 + 1e-12) s.push_back(std::round(v * 1e9) / 1e9);
    if (k > 100000) throw std::invalid_argument("--stretch: more than 100000 load steps");
  }
  return s;
}

std::string read_text(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void write_text(const fs::path& p, const std::string& text) {
  AtomicOutput out(p.string());
  {
    std::ofstream f(out.temp_path());
    f << text;
    if (!f) throw FileError(p.string(), "", "write failed");
  }
  out.commit();
}

std::string step_name(int k) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "step_%03d", k);
  return buf;
}

// load_width: the strip's (yarn::Strip::load_width), for the last column.
std::string csv_line(int k, const yarn::StretchStep& r, double load_width) {
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "%d,%.9g,%.10g,%.10g,%.10g,%.10g,%.3e,%.12g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.3e,%.3f,%.3f,%.3f,%.4f,%d,%d,%s,%.10g\n",
                k, r.stretch, r.tension, r.force, r.force_low, r.force_high,
                r.force != 0 ? (r.force_low + r.force_high) / std::abs(r.force) : 0.0, r.energy, r.parts.stretch,
                r.parts.bend, r.parts.twist, r.parts.contact, r.parts.barrier, r.solve.iterations, r.solve.residual,
                r.solve.seconds, r.solve.assembly_seconds, r.solve.factor_seconds, r.min_distance,
                r.certificate.valid ? 1 : 0, r.certificate.moves, yarn::to_string(r.solve.status), r.force / load_width);
  return buf;
}

void run(const StripOpts& o) {
  using Clock = std::chrono::steady_clock;
  const auto t_start = Clock::now();
  if (o.threads > 0) omp_set_num_threads(o.threads);
  // CHOLMOD's BLAS on one thread: its spinning workers would take the cores from the OpenMP
  // assembly between factorizations (core/blas_threads.hpp). An explicit OPENBLAS_NUM_THREADS wins.
  if (!std::getenv("OPENBLAS_NUM_THREADS")) set_blas_threads(1);
  retain_freed_memory();  // each iteration reallocates the same large arrays (core/heap_policy.hpp)
  check_output_folder(o.out, "-o");  // before any work
  const std::vector<double> size = parse_numbers(o.size, "--size");
  if (size.size() != 2 || !(size[0] > 0 && size[1] > 0))
    throw std::invalid_argument("--size: expected WIDTH,LENGTH in metres, both positive (e.g. 0.05,0.10)");
  if (o.direction != "course" && o.direction != "wale")
    throw std::invalid_argument("--direction: 'course' or 'wale', got '" + o.direction + "'");
  if (o.newton != "trust-region" && o.newton != "switched")
    throw std::invalid_argument("--newton: 'trust-region' or 'switched', got '" + o.newton + "'");
  const std::vector<double> stretches = parse_stretches(o.stretch);
  if (!(2 * o.clamp < size[1]))
    throw std::invalid_argument("--clamp " + std::to_string(o.clamp) + ": the two clamp bands cover the whole strip (" +
                                "each must be shorter than half the length, " + std::to_string(size[1]) + " m)");
  const yarn::Material mat = o.material.empty() ? yarn::Material{} : yarn::read_material(o.material);

  yarn::StripSpec spec;
  spec.width = size[0];
  spec.length = size[1];
  spec.axis = o.direction == "course" ? yarn::StripAxis::kCourse : yarn::StripAxis::kWale;
  spec.connector_scale = o.connector_scale;
  spec.bind_off = !o.no_bind_off;

  // Settings: everything that changes the result except the list of load steps (a longer list
  // extends a finished run). The pattern by its content (FNV-1a of its canonical text), so that
  // the same file reached by another path resumes and an edited one does not.
  const yarn::Pattern raw = load_pattern(o.pattern);
  uint64_t digest = 1469598103934665603ull;
  for (unsigned char c : yarn::format_pyp(raw)) digest = (digest ^ c) * 1099511628211ull;
  std::ostringstream set;
  set.precision(17);
  set << "# yarnhom strip: a rerun with these settings resumes; other settings are refused\n"
      << "pattern = " << raw.name << "\npattern_fnv1a = " << std::hex << digest << std::dec
      << "\nwidth = " << spec.width << "\nlength = " << spec.length << "\ndirection = " << o.direction
      << "\nclamp = " << o.clamp << "\nconnector_scale = " << spec.connector_scale
      << "\nbind_off = " << (spec.bind_off ? "true" : "false") << "\ntolerance = " << o.tolerance
      << "\nnewton = " << o.newton << "\n"
      << yarn::format_material(mat);
  const std::string settings = set.str();
  const fs::path dir(o.out);
  if (o.restart && fs::exists(dir / "settings.txt")) {
    fs::remove_all(dir / "steps");
    fs::remove_all(dir / "centrelines");
    fs::remove(dir / "force.csv");
    fs::remove(dir / "settings.txt");
  }
  for (const fs::path& sub : {dir, dir / "steps", dir / "centrelines"}) {
    check_output_folder(sub.string(), "-o");
    fs::create_directories(sub);
  }
  // Temporary files of runs killed while writing (AtomicOutput's "FILE.partial-PID"): those of
  // processes that no longer run are removed, with a line.
  for (const fs::path& sub : {dir, dir / "steps", dir / "centrelines"})
    for (const auto& e : fs::directory_iterator(sub)) {
      const std::string name = e.path().string();
      const size_t at = name.rfind(".partial-");
      if (at == std::string::npos) continue;
      for (const std::string& t : AtomicOutput::remove_stale_temporaries(name.substr(0, at)))
        std::fprintf(stderr, "yarnhom: removed %s, a temporary file left by an interrupted run\n", t.c_str());
    }
  // The files written below must be writable regular files (not folders, devices, FIFOs) and
  // none of the inputs.
  std::vector<std::string> inputs;
  if (fs::exists(o.pattern)) inputs.push_back(o.pattern);
  if (!o.material.empty()) inputs.push_back(o.material);
  for (const char* f : {"settings.txt", "force.csv", "strip.obj"}) check_output_file((dir / f).string(), inputs, "-o");
  if (fs::exists(dir / "settings.txt")) {
    const std::string old = read_text(dir / "settings.txt");
    if (old != settings) {
      std::istringstream a(old), b(settings);
      std::string la, lb;
      while (std::getline(a, la) && std::getline(b, lb) && la == lb) {
      }
      throw std::invalid_argument(o.out + " holds a strip run with other settings ('" + la + "' there, '" + lb +
                                  "' now): choose another -o, or pass --restart to discard it");
    }
  } else {
    write_text(dir / "settings.txt", settings);
  }

  // The strip: the tile relaxed at rest (its stored rest state is the material's, its
  // geometry not an equilibrium), tiled, cut, joined.
  std::fprintf(stderr, "yarnhom strip: relaxing the tile of '%s' at rest (stress-free period)\n", raw.name.c_str());
  yarn::RestOptions rest;
  rest.max_seconds = o.rest_time_limit;
  const yarn::StripTile tile = yarn::rest_tile(raw, mat, rest);
  yarn::Strip strip = yarn::generate_strip(tile, spec);
  const std::vector<signed char> clamp = yarn::clamp_flags(strip, o.clamp);
  const yarn::StripProblem P(strip, mat, clamp);
  const yarn::StripStretch S(P, strip.long_axis(), strip.x);
  yarn::write_centrelines((dir / "strip.obj").string(), strip, strip.x);
  int nconn = 0, nclamped = 0;
  for (auto c : strip.connector_edge) nconn += c;
  for (auto c : clamp) nclamped += c != 0;
  std::printf("strip       %s: %.4g x %.4g m (%s), %d x %d tiles, relaxed lattice (%.5g, 0), (%.5g, %.5g) m; "
              "load width %.5g m (the rows along the long axis)\n",
              strip.name.c_str(), strip.width, strip.length, o.direction.c_str(), strip.tiles_x, strip.tiles_y,
              tile.lattice(0, 0), tile.lattice(0, 1), tile.lattice(1, 1), strip.load_width);
  std::printf("yarn        %d vertices (%d rows + %d bind-off rows, %d connectors, %d of %d edges boundary yarn at "
              "%.4g of the moduli), %d clamped, %d unknowns\n",
              strip.size(), strip.rows, strip.boundary_rows, strip.connectors, nconn, strip.num_edges(),
              strip.connector_scale, nclamped, P.num_dofs());
  std::printf("solver      CHOLMOD on %s; assembly on %d thread(s)\n", blas_description(), omp_get_max_threads());
  std::fflush(stdout);

  // Load steps: reuse the step files that match, compute the rest.
  yarn::StripSolveOptions sopt;
  sopt.tolerance = o.tolerance;
  sopt.max_iterations = o.max_iterations;
  sopt.verbose = o.verbose;
  sopt.method = o.newton == "switched" ? yarn::StripSolveOptions::Method::kSwitched
                                       : yarn::StripSolveOptions::Method::kTrustRegion;
  std::vector<yarn::StretchStep> done;
  yarn::StripState st = P.initial_state();
  double from = 1.0;
  int computed = 0;
  double compute_seconds = 0;
  bool failed = false;
  auto write_force_csv = [&] {
    std::string csv =
        "step,stretch,tension_N_per_m,force_N,force_low_N,force_high_N,balance,energy_J,stretch_J,bend_J,twist_J,"
        "contact_J,barrier_J,iterations,residual,seconds,assembly_seconds,factor_seconds,min_distance,certified,"
        "checked_moves,status,tension_load_N_per_m\n";
    for (size_t j = 0; j < done.size(); ++j) csv += csv_line(int(j), done[j], strip.load_width);
    write_text(dir / "force.csv", csv);
  };
  for (size_t k = 0; k < stretches.size(); ++k) {
    const fs::path step_file = dir / "steps" / (step_name(int(k)) + ".h5");
    if (fs::exists(step_file) && computed == 0) {
      yarn::StripState loaded;
      yarn::StretchStep r = yarn::read_step(step_file.string(), P, loaded);
      if (std::abs(r.stretch - stretches[k]) < 1e-12 && r.solve.converged() && r.certificate.valid) {
        st = std::move(loaded);
        r.parts = yarn::EnergyParts{};
        P.evaluate(st, nullptr, nullptr, &r.parts);
        done.push_back(r);
        from = stretches[k];
        std::fprintf(stderr, "yarnhom strip: step %zu/%zu (stretch %.3f) kept from %s\n", k + 1, stretches.size(),
                     stretches[k], step_file.string().c_str());
        continue;
      }
    }
    // From here on everything is recomputed: drop stale later files.
    for (size_t j = k; fs::exists(dir / "steps" / (step_name(int(j)) + ".h5")); ++j) {
      fs::remove(dir / "steps" / (step_name(int(j)) + ".h5"));
      fs::remove(dir / "centrelines" / (step_name(int(j)) + ".obj"));
    }
    const auto t0 = Clock::now();
    yarn::StretchStep r = S.step(st, from, stretches[k], sopt);
    compute_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++computed;
    from = stretches[k];
    done.push_back(r);
    // Only certified equilibria are saved: every move from the generated strip kept every pair
    // of segments above d_min (no yarn passed through another).
    const bool ok = r.solve.converged() && r.certificate.valid;
    if (ok) {
      yarn::write_step(step_file.string(), strip, r, st);
      yarn::write_centrelines((dir / "centrelines" / (step_name(int(k)) + ".obj")).string(), strip, st.x);
    }
    write_force_csv();
    if (o.verbose) std::fprintf(stderr, "yarnhom strip: %s\n", r.solve.summary().c_str());
    const size_t left = stretches.size() - k - 1;
    std::fprintf(stderr,
                 "yarnhom strip: step %zu/%zu  stretch %.3f  %.6g N/m  (clamps %.4g / %.4g N)  %d iterations  %s  "
                 "| elapsed %s, ETA %s\n",
                 k + 1, stretches.size(), r.stretch, r.tension, r.force_low, r.force_high, r.solve.iterations,
                 format_seconds(r.solve.seconds).c_str(),
                 format_seconds(std::chrono::duration<double>(Clock::now() - t_start).count()).c_str(),
                 format_seconds(left * compute_seconds / computed).c_str());
    if (!ok) {
      if (!r.solve.converged())
        std::fprintf(stderr, "yarnhom: error: load step %zu (stretch %.3f) did not converge: %s\n", k + 1, stretches[k],
                     r.solve.summary().c_str());
      else
        std::fprintf(stderr, "yarnhom: error: load step %zu (stretch %.3f) has no topology certificate: %s\n", k + 1,
                     stretches[k], yarn::summary(r.certificate, 2 * strip.radius).c_str());
      failed = true;
      break;
    }
  }

  // Also when every step was kept: a run killed between a step file and force.csv left the
  // table one row short.
  if (computed == 0 && !done.empty()) write_force_csv();
  std::printf("%-6s %-8s %-14s %-12s %-10s %-6s %s\n", "step", "stretch", "tension N/m", "force N", "balance", "iter",
              "seconds");
  for (size_t j = 0; j < done.size(); ++j)
    std::printf("%-6zu %-8.3f %-14.6g %-12.6g %-10.2e %-6d %.2f\n", j, done[j].stretch, done[j].tension, done[j].force,
                done[j].force != 0 ? (done[j].force_low + done[j].force_high) / std::abs(done[j].force) : 0.0,
                done[j].solve.iterations, done[j].solve.seconds);
  std::printf("output      %s (force.csv, steps/, centrelines/)\n", o.out.c_str());

  if (!o.no_plots) {
    const std::string py = find_python();
    const std::string script = (fs::path(scripts_dir()) / "plot" / "plot_strip.py").string();
    if (py.empty() || !fs::exists(script)) {
      std::fprintf(stderr,
                   "yarnhom strip: no python3 with matplotlib, h5py and numpy (tried $YARNHOM_PYTHON, /usr/bin/python3, "
                   "python3), or no %s: no PNGs; the numbers are in %s\n",
                   script.c_str(), o.out.c_str());
    } else {
      // A child without a shell that dies with this process (tools/child_process.hpp).
      const int rc = run_child({py, script, o.out});
      if (rc != 0) std::fprintf(stderr, "yarnhom strip: the plot script %s failed (exit status %d)\n", script.c_str(), rc);
      else std::printf("pictures    strip.png, deformed.png, force.png\n");
    }
  }
  if (failed) throw ExitCode{2};
}

}  // namespace

void register_strip(CLI::App& app) {
  auto o = std::make_shared<StripOpts>();
  auto* cmd = app.add_subcommand(
      "strip",
      "Yarn-level fabric strip stretch test (docs/strip.md; supplement section 4.2): tiles a periodic "
      "pattern over a strip of the given size, cuts the yarns at its border, binds the knit off and joins "
      "everything into one yarn with soft boundary yarn (1/200 of the moduli), clamps both short ends and "
      "stretches it quasi-statically, each load step solved to equilibrium by Newton's method with the "
      "RVE's energy (rods, contact kernel and IPC barrier, CCD collision filter). The tile is the pattern's "
      "stress-free relaxed tile (the same rest state as produce). Writes force.csv (clamp force per undeformed width, N/m), the "
      "centrelines of every step (OBJ) and PNGs. Kill it and rerun the same command: finished load steps "
      "are kept. Exit status 2 when a load step does not converge (or, never expected, loses its topology "
      "certificate).");
  cmd->add_option("PATTERN", o->pattern, "A .pyp file, or a built-in pattern: basket, plain, stockinette")->required();
  cmd->add_option("-o,--output", o->out, "Run folder (created; a rerun resumes it)")->required();
  cmd->add_option("--size", o->size, "WIDTH,LENGTH of the strip in metres (default 0.05,0.10)");
  cmd->add_option("--direction", o->direction,
                  "course: the long axis (and the load) along the pattern's x, the course; wale: along y (default course)");
  cmd->add_option("--stretch", o->stretch,
                  "FROM:TO:STEP load steps as clamp separation / initial (default 1.0:1.7:0.05); the strip is always "
                  "relaxed at 1.0 first");
  cmd->add_option("--clamp", o->clamp, "Clamp band at each short end, metres (default 0.005): every vertex within it is held")
      ->check(finite_positive());
  cmd->add_option("--connector-scale", o->connector_scale, "Moduli of the boundary yarn relative to the yarn's, in (0, 1] (default 1/200, the supplement's). 1 gives "
                  "the selvedges the yarn's own stiffness, as in a knit where the yarn turns into the next course: our "
                  "joins are long, and at 1/200 the selvedges are nearly free (docs/accuracy.md, \"The boundary yarn's "
                  "stiffness\")")
      ->check(finite_range(1e-12, 1.0, "in (0, 1]"));
  cmd->add_option("--newton", o->newton,
                  "Newton method of each load step: trust-region (default: Steihaug-CG on the exact Hessian, "
                  "preconditioned by the projected Hessian's Cholesky factor) or switched (line searches on the "
                  "projected or the exact Hessian: the first method, slower; docs/strip.md section 4)");
  cmd->add_flag("--no-bind-off", o->no_bind_off, "Knits: no boundary course above and below (the edges may unravel)");
  cmd->add_option("--material", o->material, "Material file: 'key = value' lines (docs/yarn_material.md)")->check(existing_regular_file());
  cmd->add_option("--tolerance", o->tolerance, "Relative residual each load step converges to (default 1e-10)")
      ->check(finite_range(1e-300, 0.1, "a relative residual in (0, 0.1]"));
  cmd->add_option("--max-iterations", o->max_iterations, "Newton iterations per load step at most (default 300)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--threads", o->threads, "Threads for the assembly (0 or absent: all cores); the BLAS under CHOLMOD runs on one unless OPENBLAS_NUM_THREADS says otherwise")->check(CLI::Range(0, kMaxThreads));
  cmd->add_option("--rest-time-limit", o->rest_time_limit,
                  "Wall-clock limit of the tile's rest relaxation in seconds, 0: none (default 300; the paper's "
                  "patterns relax in seconds to a minute)")
      ->check(finite_non_negative());
  cmd->add_flag("--restart", o->restart, "Discard what the run folder holds and start again");
  cmd->add_flag("--no-plots", o->no_plots, "Write no PNGs");
  cmd->add_flag("--verbose", o->verbose, "One line per Newton iteration on stderr");
  cmd->callback([o] { run(*o); });
}

}  // namespace yarnhom::tools
