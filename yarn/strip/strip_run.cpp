#include "yarn/strip/strip_run.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/console.hpp"
#include "core/file_checks.hpp"
#include "core/heap_policy.hpp"
#include "core/number_list.hpp"
#include "core/text_file.hpp"
#include "numerics/blas_threads.hpp"
#include "yarn/rod/load_pattern.hpp"
#include "yarn/strip/strip_generate.hpp"
#include "yarn/strip/strip_io.hpp"

namespace yarnhom::yarn {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

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

std::string step_name(int k) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "step_%03d", k);
  return buf;
}

// load_width: the strip's (yarn::Strip::load_width), for the last column.
std::string csv_line(int k, const StretchStep& r, double load_width) {
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "%d,%.9g,%.10g,%.10g,%.10g,%.10g,%.3e,%.12g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.3e,%.3f,%.3f,%.3f,%.4f,%d,%d,%s,%.10g\n",
                k, r.stretch, r.tension, r.force, r.force_low, r.force_high,
                r.force != 0 ? (r.force_low + r.force_high) / std::abs(r.force) : 0.0, r.energy, r.parts.stretch,
                r.parts.bend, r.parts.twist, r.parts.contact, r.parts.barrier, r.solve.iterations, r.solve.residual,
                r.solve.seconds, r.solve.assembly_seconds, r.solve.factor_seconds, r.min_distance,
                r.certificate.valid ? 1 : 0, r.certificate.moves, to_string(r.solve.status), r.force / load_width);
  return buf;
}

void write_force_csv(const fs::path& dir, const std::vector<StretchStep>& done, double load_width) {
  std::string csv =
      "step,stretch,tension_N_per_m,force_N,force_low_N,force_high_N,balance,energy_J,stretch_J,bend_J,twist_J,"
      "contact_J,barrier_J,iterations,residual,seconds,assembly_seconds,factor_seconds,min_distance,certified,"
      "checked_moves,status,tension_load_N_per_m\n";
  for (size_t j = 0; j < done.size(); ++j) csv += csv_line(int(j), done[j], load_width);
  write_text_file((dir / "force.csv").string(), csv);
}

// A strip holds about width x length / (px py) tiles of the pattern's vertices (plus the
// bind-off rows and connectors): bounded before anything is allocated (1e9 x 1e9 m ran out of
// memory after the rest relaxation).
constexpr double kMaxStripVertices = 1e6;
void check_strip_size(const Pattern& p, double width, double length) {
  const double tiles = (width / p.py + 3) * (length / p.px + 3);  // either direction: the same area
  const double vertices = tiles * p.size();
  if (vertices <= kMaxStripVertices) return;
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "--size %g,%g: the strip would hold about %.3g yarn vertices (%.3g tiles of %s's %d-vertex %.4g x %.4g m "
                "period); at most %.0f (width x length / (px py) x vertices per tile)",
                width, length, vertices, tiles, p.name.c_str(), p.size(), p.px, p.py, kMaxStripVertices);
  throw std::invalid_argument(buf);
}

// A pattern whose rest yarn is straight and untwisted (RK = RT = 0: stocktiny, stocktiniest and
// the built-in generated patterns) stores the bending energy of its loops, which only the
// periodic tile balances: cut into a strip, the courses pull their loops out of each other and
// the relaxation at 100 % does not converge unless the clamps hold nearly all of it
// (docs/strip.md section 6). Refused at once: every course strip, and a wale strip with more
// than two courses between its clamps. Measured on stocktiny (course height 0.88 mm): wale
// strips 3.5, 8 and 15 mm wide with 1.7 mm free relax in 49, 39 and 86 Newton iterations;
// 3.2 mm free relaxes in 244 at 3.5 mm wide and fails at 8 mm, 3.5 mm free fails; course strips
// fail with 1.6 mm free (3.5 x 4 mm), 10 mm (10 x 20 mm) and the built-in stockinette's 6 mm.
constexpr double kMaxFreeCourses = 2.0;
void check_strip_holds(const Pattern& p, const StripRunOptions& o, double width, double length) {
  for (const Eigen::Vector2d& k : p.rest_kappa)
    if (!(k.norm() < 1e-9)) return;
  for (double t : p.rest_twist)
    if (!(std::abs(t) < 1e-9)) return;
  const bool course = o.direction == "course";
  const double free_length = length - 2 * o.clamp, most = kMaxFreeCourses * p.py;
  if (!course && free_length <= most) return;
  char what[400];
  if (course)
    std::snprintf(what, sizeof what, "a course strip of it does not hold at any size; a wale strip does with at most %g courses "
                  "between the clamps (length - 2 x --clamp <= %.3g mm, e.g. --direction wale --size %g,%.4g --clamp %g)",
                  kMaxFreeCourses, 1e3 * most, width, 2 * o.clamp + most, o.clamp);
  else
    std::snprintf(what, sizeof what, "a wale strip of it holds with at most %g courses between the clamps: length - 2 x --clamp "
                  "= %.4g mm here, at most %.3g mm (%g x the %.3g mm course height; e.g. --size %g,%.4g with --clamp %g)",
                  kMaxFreeCourses, 1e3 * free_length, 1e3 * most, kMaxFreeCourses, 1e3 * p.py, width, 2 * o.clamp + most, o.clamp);
  throw std::invalid_argument(
      display_name(p) + ": its rest yarn is straight and untwisted (every rest curvature and twist is 0), so its loops "
      "hold only inside the periodic tile: cut into a strip, its courses pull their loops out of each other and the "
      "relaxation at 100 % does not converge unless the clamps hold nearly all of it (measured on stocktiny; docs/strip.md "
      "section 6): " + std::string(what) + ". A pattern that stores its loops' curvature makes strips of any size (the "
      "paper's, e.g. ../shared/patterns/stockinette.pyp: a 20 x 40 mm course strip relaxes in 83 iterations)");
}

// The options checked, and what the run is.
struct StripSetup {
  std::vector<double> size, stretches;
  Material mat;
  StripSpec spec;
  Pattern raw;
  std::string settings;
};

StripSetup validate(const StripRunOptions& o) {
  StripSetup s;
  s.size = parse_numbers(o.size, "--size");
  if (s.size.size() != 2 || !(s.size[0] > 0 && s.size[1] > 0))
    throw std::invalid_argument("--size: expected WIDTH,LENGTH in metres, both positive (e.g. 0.05,0.10)");
  if (o.direction != "course" && o.direction != "wale")
    throw std::invalid_argument("--direction: 'course' or 'wale', got '" + o.direction + "'");
  if (o.newton != "trust-region" && o.newton != "switched")
    throw std::invalid_argument("--newton: 'trust-region' or 'switched', got '" + o.newton + "'");
  s.stretches = parse_stretches(o.stretch);
  if (!(2 * o.clamp < s.size[1]))
    throw std::invalid_argument("--clamp " + std::to_string(o.clamp) + ": the two clamp bands cover the whole strip (" +
                                "each must be shorter than half the length, " + std::to_string(s.size[1]) + " m)");
  s.mat = o.material.empty() ? Material{} : read_material(o.material);
  s.spec.width = s.size[0];
  s.spec.length = s.size[1];
  s.spec.axis = o.direction == "course" ? StripAxis::kCourse : StripAxis::kWale;
  s.spec.connector_scale = o.connector_scale;
  s.spec.bind_off = !o.no_bind_off;

  // Settings: everything that changes the result except the list of load steps (a longer list
  // extends a finished run). The pattern by its content (FNV-1a of its canonical text), so that
  // the same file reached by another path resumes and an edited one does not.
  s.raw = load_pattern(o.pattern);
  check_strip_size(s.raw, s.size[0], s.size[1]);
  check_strip_holds(s.raw, o, s.size[0], s.size[1]);
  uint64_t digest = 1469598103934665603ull;
  for (unsigned char c : format_pyp(s.raw)) digest = (digest ^ c) * 1099511628211ull;
  std::ostringstream set;
  set.precision(17);
  set << "# yarnhom strip: a rerun with these settings resumes; other settings are refused\n"
      << "pattern = " << s.raw.name << "\npattern_fnv1a = " << std::hex << digest << std::dec
      << "\nwidth = " << s.spec.width << "\nlength = " << s.spec.length << "\ndirection = " << o.direction
      << "\nclamp = " << o.clamp << "\nconnector_scale = " << s.spec.connector_scale
      << "\nbind_off = " << (s.spec.bind_off ? "true" : "false") << "\ntolerance = " << o.tolerance
      << "\nnewton = " << o.newton << "\n"
      << format_material(s.mat);
  s.settings = set.str();
  return s;
}

// The run folder: emptied with --restart, created, rid of the temporaries of killed runs, its
// outputs checked, and refused when it holds a run with other settings.
void prepare_run_folder(const StripRunOptions& o, const std::string& settings) {
  const fs::path dir(o.out);
  if (o.restart && fs::exists(dir / "settings.txt")) {
    fs::remove_all(dir / "steps");
    fs::remove_all(dir / "centrelines");
    fs::remove(dir / "force.csv");
    fs::remove(dir / "settings.txt");
  }
  // The files written below must be writable regular files (not folders, devices, FIFOs) and
  // none of the inputs.
  std::vector<std::string> inputs;
  if (fs::exists(o.pattern)) inputs.push_back(o.pattern);
  if (!o.material.empty()) inputs.push_back(o.material);
  prepare_output_folder(o.out, {"steps", "centrelines"}, {"settings.txt", "force.csv", "strip.obj"}, inputs);
  if (!fs::exists(dir / "settings.txt")) {
    write_text_file((dir / "settings.txt").string(), settings);
    return;
  }
  const std::string old = read_text_file((dir / "settings.txt").string());
  if (old == settings) return;
  std::istringstream a(old), b(settings);
  std::string la, lb;
  while (std::getline(a, la) && std::getline(b, lb) && la == lb) {
  }
  throw std::invalid_argument(o.out + " holds a strip run with other settings ('" + la + "' there, '" + lb +
                              "' now): choose another -o, or pass --restart to discard it");
}

void print_strip(const StripRunOptions& o, const StripTile& tile, const Strip& strip, const std::vector<signed char>& clamp,
                 const StripProblem& P) {
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
  std::printf("solver      CHOLMOD on %s; assembly on %d thread(s)\n", numerics::blas_description(), omp_get_max_threads());
  std::fflush(stdout);
}

// The load steps: reuse the step files that match, compute the rest.
class LoadSteps {
 public:
  LoadSteps(const StripRunOptions& o, const std::vector<double>& stretches, const Strip& strip, const StripProblem& P,
            Clock::time_point t_start)
      : o_(o), dir_(o.out), stretches_(stretches), strip_(strip), P_(P), S_(P, strip.long_axis(), strip.x),
        t_start_(t_start), st_(P.initial_state()) {
    sopt_.tolerance = o.tolerance;
    sopt_.max_iterations = o.max_iterations;
    sopt_.verbose = o.verbose;
    sopt_.method = o.newton == "switched" ? StripSolveOptions::Method::kSwitched : StripSolveOptions::Method::kTrustRegion;
  }

  // Returns false when a step failed (the run stops there).
  bool run() {
    for (size_t k = 0; k < stretches_.size(); ++k) {
      if (computed_ == 0 && keep(k)) continue;
      if (!compute(k)) return false;
    }
    // Also when every step was kept: a run killed between a step file and force.csv left the
    // table one row short.
    if (computed_ == 0 && !done_.empty()) write_force_csv(dir_, done_, strip_.load_width);
    return true;
  }

  const std::vector<StretchStep>& done() const { return done_; }

 private:
  fs::path step_file(size_t k) const { return dir_ / "steps" / (step_name(int(k)) + ".h5"); }
  fs::path centrelines_file(size_t k) const { return dir_ / "centrelines" / (step_name(int(k)) + ".obj"); }

  // A step file of a converged, certified step at this stretch: kept.
  bool keep(size_t k) {
    if (!fs::exists(step_file(k))) return false;
    StripState loaded;
    StretchStep r = read_step(step_file(k).string(), P_, loaded);
    if (!(std::abs(r.stretch - stretches_[k]) < 1e-12 && r.solve.converged() && r.certificate.valid)) return false;
    st_ = std::move(loaded);
    r.parts = EnergyParts{};
    P_.evaluate(st_, nullptr, nullptr, &r.parts);
    done_.push_back(r);
    from_ = stretches_[k];
    std::fprintf(stderr, "yarnhom strip: step %zu/%zu (stretch %.3f) kept from %s\n", k + 1, stretches_.size(),
                 stretches_[k], step_file(k).string().c_str());
    return true;
  }

  bool compute(size_t k) {
    // From here on everything is recomputed: drop stale later files.
    for (size_t j = k; fs::exists(step_file(j)); ++j) {
      fs::remove(step_file(j));
      fs::remove(centrelines_file(j));
    }
    const auto t0 = Clock::now();
    StretchStep r = S_.step(st_, from_, stretches_[k], sopt_);
    compute_seconds_ += std::chrono::duration<double>(Clock::now() - t0).count();
    ++computed_;
    from_ = stretches_[k];
    done_.push_back(r);
    // Only certified equilibria are saved: every move from the generated strip kept every pair
    // of segments above d_min (no yarn passed through another).
    const bool ok = r.solve.converged() && r.certificate.valid;
    if (ok) {
      write_step(step_file(k).string(), strip_, r, st_);
      write_centrelines(centrelines_file(k).string(), strip_, st_.x);
    }
    write_force_csv(dir_, done_, strip_.load_width);
    if (o_.verbose) std::fprintf(stderr, "yarnhom strip: %s\n", r.solve.summary().c_str());
    const size_t left = stretches_.size() - k - 1;
    std::fprintf(stderr,
                 "yarnhom strip: step %zu/%zu  stretch %.3f  %.6g N/m  (clamps %.4g / %.4g N)  %d iterations  %s  "
                 "| elapsed %s, ETA %s\n",
                 k + 1, stretches_.size(), r.stretch, r.tension, r.force_low, r.force_high, r.solve.iterations,
                 format_seconds(r.solve.seconds).c_str(),
                 format_seconds(std::chrono::duration<double>(Clock::now() - t_start_).count()).c_str(),
                 format_seconds(left * compute_seconds_ / computed_).c_str());
    if (ok) return true;
    if (!r.solve.converged())
      std::fprintf(stderr, "yarnhom: error: load step %zu (stretch %.3f) did not converge: %s\n", k + 1, stretches_[k],
                   r.solve.summary().c_str());
    else
      std::fprintf(stderr, "yarnhom: error: load step %zu (stretch %.3f) has no topology certificate: %s\n", k + 1,
                   stretches_[k], summary(r.certificate, 2 * strip_.radius).c_str());
    return false;
  }

  const StripRunOptions& o_;
  const fs::path dir_;
  const std::vector<double>& stretches_;
  const Strip& strip_;
  const StripProblem& P_;
  const StripStretch S_;
  const Clock::time_point t_start_;
  StripSolveOptions sopt_;
  StripState st_;
  std::vector<StretchStep> done_;
  double from_ = 1.0, compute_seconds_ = 0;
  int computed_ = 0;
};

// A rerun with fewer load steps (a shorter --stretch): the step files and centrelines of the
// earlier run's later steps are removed, saying so in one line, so that the folder holds what
// force.csv lists (accuracy counts the centrelines).
void remove_steps_beyond(const fs::path& dir, size_t n) {
  int removed = 0;
  std::error_code ec;
  for (size_t k = n;; ++k) {
    const bool a = fs::remove(dir / "steps" / (step_name(int(k)) + ".h5"), ec);
    const bool b = fs::remove(dir / "centrelines" / (step_name(int(k)) + ".obj"), ec);
    if (!a && !b) break;
    ++removed;
  }
  if (removed)
    std::fprintf(stderr, "yarnhom strip: removed %d load step(s) of an earlier run beyond this run's %zu (%s .. %s)\n", removed,
                 n, step_name(int(n)).c_str(), step_name(int(n) + removed - 1).c_str());
}

void print_force_table(const std::vector<StretchStep>& done, const std::string& out) {
  std::printf("%-6s %-8s %-14s %-12s %-10s %-6s %s\n", "step", "stretch", "tension N/m", "force N", "balance", "iter",
              "seconds");
  for (size_t j = 0; j < done.size(); ++j)
    std::printf("%-6zu %-8.3f %-14.6g %-12.6g %-10.2e %-6d %.2f\n", j, done[j].stretch, done[j].tension, done[j].force,
                done[j].force != 0 ? (done[j].force_low + done[j].force_high) / std::abs(done[j].force) : 0.0,
                done[j].solve.iterations, done[j].solve.seconds);
  std::printf("output      %s (force.csv, steps/, centrelines/)\n", out.c_str());
}

}  // namespace

void check_strip_options(const StripRunOptions& o) { validate(o); }

int run_strip(const StripRunOptions& o) {
  const auto t_start = Clock::now();
  if (o.threads > 0) omp_set_num_threads(o.threads);
  // CHOLMOD's BLAS on one thread: its spinning workers would take the cores from the OpenMP
  // assembly between factorizations (numerics/blas_threads.hpp). An explicit OPENBLAS_NUM_THREADS wins.
  if (!std::getenv("OPENBLAS_NUM_THREADS")) numerics::set_blas_threads(1);
  retain_freed_memory();  // each iteration reallocates the same large arrays (core/heap_policy.hpp)
  check_output_folder(o.out, "-o");  // before any work
  const StripSetup s = validate(o);
  prepare_run_folder(o, s.settings);

  // The strip: the tile relaxed at rest (its stored rest state is the material's, its
  // geometry not an equilibrium), tiled, cut, joined.
  std::fprintf(stderr, "yarnhom strip: relaxing the tile of '%s' at rest (stress-free period)\n", s.raw.name.c_str());
  RestOptions rest;
  rest.max_seconds = o.rest_time_limit;
  const StripTile tile = rest_tile(s.raw, s.mat, rest);
  const Strip strip = generate_strip(tile, s.spec);
  const std::vector<signed char> clamp = clamp_flags(strip, o.clamp);
  const StripProblem P(strip, s.mat, clamp);
  write_centrelines((fs::path(o.out) / "strip.obj").string(), strip, strip.x);
  print_strip(o, tile, strip, clamp, P);

  LoadSteps steps(o, s.stretches, strip, P, t_start);
  const bool ok = steps.run();
  if (ok) remove_steps_beyond(fs::path(o.out), s.stretches.size());
  print_force_table(steps.done(), o.out);
  return ok ? 0 : 2;
}

}  // namespace yarnhom::yarn
