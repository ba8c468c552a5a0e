// yarnhom rve: the yarn RVE of a pattern at one macroscopic strain: Psi, dPsi/ds, the solver's
// report; optionally the equilibrium state (HDF5) and a tube mesh of the yarns (OBJ).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "core/scaled_eigen.hpp"
#include "yarn/rest_hessian.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"
#include "yarn/energy_density.hpp"
#include "yarn/generate.hpp"
#include "yarn/relax.hpp"
#include "yarn/rest.hpp"
#include "yarn/rve_ccd.hpp"
#include "yarn/state_io.hpp"

namespace yarnhom::tools {
namespace {

struct RveOpts {
  std::string pattern, strain = "0,0,0,0,0,0", material, out, obj, start, pattern_out, certify, tile = "1,1";
  bool json = false, verbose = false, fixed_period = false, no_ccd = false, rest_hessian = false;
  double tolerance = 1e-10, time_limit = 300;
  int max_iterations = 500;
};

yarn::Pattern load_pattern(const std::string& what) {
  if (std::filesystem::exists(what)) {
    check_input_file(what, "PATTERN");
    return yarn::read_pyp(what);
  }
  if (yarn::is_builtin_pattern(what)) return yarn::builtin_pattern(what);
  std::string names;
  for (const auto& n : yarn::builtin_pattern_names()) names += (names.empty() ? "" : ", ") + n;
  throw std::invalid_argument("pattern '" + what + "' is neither a file nor a built-in pattern (" + names + ")");
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// --certify: re-checks the path recorded in a state file from scratch.
void certify(const RveOpts& o, const yarn::RveProblem& rve) {
  const yarn::RveState st = yarn::read_state(o.certify, rve);
  const double two_r = 2 * rve.radius();
  std::printf("state       %s\n", o.certify.c_str());
  std::printf("claimed     %s\n", yarn::summary(st.certificate, two_r).c_str());
  if (st.path.empty()) {
    std::printf("re-checked  nothing: the file holds no recorded path (write it with yarnhom rve --out)\n");
    throw ExitCode{3};
  }
  yarn::ContactCertificate c = yarn::certify_path(rve, st.path, rve.min_separation());
  const yarn::PathPoint& last = st.path.back();
  if (!(last.s == st.anchor.s && last.u == st.u)) yarn::invalidate(c, "the recorded path does not end at the saved state");
  std::printf("re-checked  %s (%zu configurations)\n", yarn::summary(c, two_r).c_str(), st.path.size());
  if (!c.valid) throw ExitCode{3};
}

void run(const RveOpts& o) {
  // Outputs: checked before any work, never one of the inputs, never each other.
  const std::vector<std::string> inputs = {o.pattern, o.material, o.start};
  std::vector<std::pair<std::string, std::string>> outs;
  if (!o.out.empty()) outs.push_back({prepare_output(o.out, inputs, "--out"), "--out"});
  if (!o.obj.empty()) outs.push_back({prepare_output(o.obj, inputs, "--obj"), "--obj"});
  if (!o.pattern_out.empty()) outs.push_back({prepare_output(o.pattern_out, inputs, "--pattern-out"), "--pattern-out"});
  for (size_t i = 0; i < outs.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (std::filesystem::weakly_canonical(outs[i].first) == std::filesystem::weakly_canonical(outs[j].first))
        throw std::invalid_argument(outs[j].second + " and " + outs[i].second + " name the same file " + outs[i].first);
  const std::vector<double> sv = parse_numbers(o.strain, "--strain");
  if (sv.size() != 6)
    throw std::invalid_argument("--strain: expected 6 comma-separated values (s_x,s_a,s_y,II_x,II_a,II_y), got " +
                                std::to_string(sv.size()));
  yarn::Strain s = Eigen::Map<const yarn::Strain>(sv.data());
  for (int k = 0; k < 6; ++k)
    if (std::string rule = strain_domain_violation(k, s[k]); !rule.empty()) throw std::invalid_argument("--strain: " + rule);
  const yarn::Material mat = o.material.empty() ? yarn::Material{} : yarn::load_material(o.material);
  const auto [nx, ny] = parse_tiles(o.tile, "--tile");
  const yarn::Pattern base = load_pattern(o.pattern);
  const yarn::Pattern pattern = nx * ny > 1 ? yarn::tile(base, nx, ny) : base;
  if (!o.certify.empty()) {
    const yarn::RveProblem rve(pattern, mat, yarn::RveOptions{}, yarn::read_state_reference(o.certify));
    return certify(o, rve);
  }
  yarn::SolveOptions opt;
  opt.ccd = !o.no_ccd;
  opt.tolerance = o.tolerance;
  opt.max_iterations = o.max_iterations;
  opt.max_seconds = o.time_limit;
  opt.verbose = o.verbose;

  // The reference: the pattern relaxed at rest, its period included (s = 0 is then the
  // stress-free tile; docs/rve.md section 6), or the reference a given state was solved in.
  // With --out the whole path (from the pattern's own geometry) is recorded in the state file,
  // for --certify.
  std::unique_ptr<yarn::RveProblem> rve;
  yarn::RveState st;
  yarn::RestReport rest;
  bool relaxed = false;
  if (!o.start.empty()) {
    if (!o.pattern_out.empty()) throw std::invalid_argument("--pattern-out needs the rest relaxation: drop --start");
    rve = std::make_unique<yarn::RveProblem>(pattern, mat, yarn::RveOptions{}, yarn::read_state_reference(o.start));
    st = yarn::read_state(o.start, *rve);
    if (o.out.empty()) st.path.clear();
  } else {
    yarn::RestOptions ro;
    ro.free_period = !o.fixed_period;
    ro.solve = opt;  // --max-iterations and --time-limit bound the rest relaxation too
    ro.first_max_iterations = opt.max_iterations;
    ro.max_seconds = o.time_limit;
    ro.verbose = o.verbose;
    ro.record_path = !o.out.empty();
    // A tiling is the same material on a larger RVE: the pattern's relaxed rest repeated.
    yarn::RestTile tile = yarn::repeat_rest(base, yarn::relax_tile(base, mat, ro), nx, ny);
    rve = std::make_unique<yarn::RveProblem>(std::move(tile.rve));
    st = std::move(tile.state);
    rest = tile.report;
    relaxed = true;
    if (!o.pattern_out.empty()) {
      if (rve->reference()(0, 1) != 0.0)
        throw std::invalid_argument("--pattern-out: the relaxed tile of '" + pattern.name +
                                    "' is sheared (s_a = " + std::to_string(rest.strain[1]) +
                                    "), which a .pyp tile (px x py) cannot hold; add --fixed-period");
      yarn::write_pyp(o.pattern_out, yarn::pattern_at(*rve, st));
    }
  }
  const yarn::DensityResult at_rest = yarn::evaluate_density(*rve, yarn::Strain::Zero(), st);
  yarn::RestHessian rh;
  if (o.rest_hessian) {
    if (!relaxed) throw std::invalid_argument("--rest-hessian needs the rest relaxation: drop --start");
    rh = yarn::rest_hessian(*rve, st, opt);
    if (!rh.ok) throw std::runtime_error("--rest-hessian: " + rh.failure);
  }
  const yarn::DensityResult r = yarn::energy_density(*rve, s, st, opt);
  if (!o.out.empty()) yarn::write_state(o.out, *rve, s, st, r);
  if (!o.obj.empty()) yarn::write_obj(o.obj, *rve, s, st);
  const Eigen::Matrix2d L0 = Eigen::Vector2d(pattern.px, pattern.py).asDiagonal(), L = rve->lattice();
  auto vec = [](const double* v, int n) {
    std::string out = "[";
    for (int k = 0; k < n; ++k) out += (k ? "," : "") + json_number(v[k]);
    return out + "]";
  };
  auto lattice = [&](const Eigen::Matrix2d& M) {  // rows: the two lattice vectors
    const double a[2] = {M(0, 0), M(1, 0)}, b[2] = {M(0, 1), M(1, 1)};
    return "[" + vec(a, 2) + "," + vec(b, 2) + "]";
  };

  if (o.json) {
    std::string g;
    for (int k = 0; k < 6; ++k) g += (k ? "," : "") + json_number(r.grad[k]);
    std::printf(
        "{\"pattern\":\"%s\",\"psi\":%s,\"grad\":[%s],\"iterations\":%d,\"residual\":%s,\"seconds\":%s,"
        "\"converged\":%s,\"status\":\"%s\",\"energy\":%s,\"rest_iterations\":%d,"
        "\"rest_period_updates\":%d,\"psi0\":%s,\"rest_grad\":%s,\"lattice_original\":%s,"
        "\"lattice_relaxed\":%s,\"reference_strain\":%s,\"areal_density\":%s,\"certificate_valid\":%s,"
        "\"min_separation\":%s,\"d_min\":%s,\"barrier_energy\":%s%s}\n",
        pattern.name.c_str(), json_number(r.psi).c_str(), g.c_str(), r.report.iterations,
        json_number(r.report.residual).c_str(), json_number(r.report.seconds).c_str(),
        r.report.converged() ? "true" : "false", yarn::to_string(r.report.status),
        json_number(r.report.energy).c_str(), relaxed ? rest.inner_iterations : 0, relaxed ? rest.iterations : 0,
        json_number(at_rest.psi).c_str(), vec(at_rest.grad.data(), 6).c_str(), lattice(L0).c_str(),
        lattice(L).c_str(), vec(yarn::in_plane_strain(rve->reference()).data(), 3).c_str(),
        json_number(yarn::areal_density(*rve)).c_str(), st.certificate.valid ? "true" : "false",
        json_number(st.certificate.min_distance / (2 * rve->radius())).c_str(),
        json_number(rve->min_separation() / (2 * rve->radius())).c_str(), json_number(r.parts.barrier).c_str(),
        o.rest_hessian ? (",\"rest_hessian\":" + vec(rh.H.data(), 36) + ",\"rest_hessian_smallest_scaled_eigenvalue\":" +
                          json_number(scaled_eigen(rh.H).values[0]) + ",\"rest_hessian_asymmetry\":" +
                          json_number(rh.asymmetry)).c_str()
                       : "");
  } else {
    std::printf("pattern     %s (%d vertices, %zu yarns, %d unknowns)\n", pattern.name.c_str(),
                pattern.size(), rve->topo().yarns.size(), rve->num_dofs());
    if (relaxed) std::printf("rest        %s\n", rest.summary().c_str());
    std::printf("period      pattern (%.6g, 0) (0, %.6g) m; reference (%.6g, %.6g) (%.6g, %.6g) m%s\n", L0(0, 0),
                L0(1, 1), L(0, 0), L(1, 0), L(0, 1), L(1, 1),
                rve->reference().isIdentity(0.0) ? " (the pattern's: pre-stressed)" : " (relaxed: stress free)");
    std::printf("at rest     Psi0 %.10g J/m^2, dPsi/ds %.4g %.4g %.4g, dPsi/dII %.6g %.6g %.6g J/m\n",
                at_rest.psi, at_rest.grad[0], at_rest.grad[1], at_rest.grad[2], at_rest.grad[3], at_rest.grad[4],
                at_rest.grad[5]);
    if (o.rest_hessian) {
      const ScaledEigen se = scaled_eigen(rh.H);
      std::printf("rest Hessian d2Psi/ds2 at s = 0 (rows and columns s_x s_a s_y II_x II_a II_y; %d solves, steps %.3g "
                  "and %.3g 1/m, asymmetry %.1e):\n", rh.solves, rh.step[0], rh.step[3], rh.asymmetry);
      for (int i = 0; i < 6; ++i) {
        std::printf("           ");
        for (int j = 0; j < 6; ++j) std::printf(" %12.5g", rh.H(i, j));
        std::printf("\n");
      }
      std::printf("            %s: smallest scaled eigenvalue %.3g\n", se.stable() ? "stable" : "UNSTABLE",
                  se.values[0]);
    }
    std::printf("density     %.6g kg/m^2 (yarn %.6g kg/m^3)\n", yarn::areal_density(*rve), mat.density);
    std::printf("strain      s_x %g  s_a %g  s_y %g  II_x %g  II_a %g  II_y %g (1/m)\n", s[0], s[1], s[2], s[3], s[4], s[5]);
    std::printf("solve       %s\n", r.report.summary().c_str());
    std::printf("Psi         %.10g J/m^2\n", r.psi);
    std::printf("dPsi/ds     %.8g %.8g %.8g %.8g %.8g %.8g\n", r.grad[0], r.grad[1], r.grad[2], r.grad[3], r.grad[4], r.grad[5]);
    std::printf("energy      stretch %.4g  bend %.4g  twist %.4g  contact %.4g  barrier %.4g J\n", r.parts.stretch,
                r.parts.bend, r.parts.twist, r.parts.contact, r.parts.barrier);
    std::printf("topology    %s\n", yarn::summary(st.certificate, 2 * rve->radius()).c_str());
    if (!o.out.empty()) std::printf("state       %s\n", o.out.c_str());
    if (!o.obj.empty()) std::printf("mesh        %s\n", o.obj.c_str());
  }
  if (!r.report.converged()) {
    std::fprintf(stderr, "yarnhom: error: the RVE solve did not converge: %s\n", r.report.summary().c_str());
    if (r.report.status == yarn::SolveStatus::kInfeasibleStart)
      std::fprintf(stderr, "yarnhom: the strain is too far from the start for one step: solve at an intermediate strain "
                           "first (--out), then --start from it\n");
    throw ExitCode{2};
  }
  if (!st.certificate.valid) {
    std::fprintf(stderr, "yarnhom: error: the solution is not certified to have the rest state's topology: %s\n",
                 yarn::summary(st.certificate, 2 * rve->radius()).c_str());
    throw ExitCode{3};
  }
}

}  // namespace

void register_rve(CLI::App& app) {
  auto o = std::make_shared<RveOpts>();
  auto* cmd = app.add_subcommand(
      "rve",
      "Solve the periodic yarn RVE of a pattern at one macroscopic strain (docs/rve.md): relaxes "
      "the pattern at rest (yarns and tile period: s = 0 is the stress-free tile), then minimizes "
      "the energy at the strain with Newton's method, every step filtered by collision detection so "
      "that no yarn passes through another. Prints the pattern's and the relaxed periods, Psi0 and "
      "dPsi/ds at rest (the natural bending moment dPsi/dII), the areal density, Psi (J/m^2 of the "
      "relaxed tile), dPsi/ds (envelope theorem), iterations, final residual, time and the topology "
      "certificate. Exit status 2 when the solve does not converge, 3 when the result is not certified.");
  cmd->add_option("PATTERN", o->pattern, "A .pyp file, or a built-in pattern: basket, plain, stockinette")->required();
  cmd->add_option("--strain", o->strain, "s_x,s_a,s_y,II_x,II_a,II_y (II in 1/m; default 0,0,0,0,0,0)");
  cmd->add_option("--material", o->material,
                  "Yarn material: a file of 'key = value' lines, or a built-in name: hylc-calibrated (the default), "
                  "yarnhom-2025 (the constants before issue 10); docs/yarn_material.md");
  cmd->add_option("--out", o->out, "Write the equilibrium state (HDF5)");
  cmd->add_option("--obj", o->obj, "Write a tube mesh of the yarns (OBJ)");
  cmd->add_option("--pattern-out", o->pattern_out,
                  "Write the pattern relaxed at rest as .pyp (its geometry is then an equilibrium)");
  cmd->add_option("--start", o->start,
                  "Start from this state file (warm start) instead of the relaxed rest state; the strain is then "
                  "measured from the reference tile the file was solved in")
      ->check(existing_regular_file());
  cmd->add_flag("--fixed-period", o->fixed_period,
                "Relax the yarns at the pattern's own period only (the tile stays pre-stressed: dPsi/ds(0) != 0); "
                "default: the period relaxes too and s = 0 is the stress-free tile");
  cmd->add_option("--tile", o->tile,
                  "NX,NY: solve the pattern tiled NX x NY times, from its relaxed rest repeated (a larger RVE of "
                  "the same material: in-plane strains give the same Psi, curvature shows the map's tile-size "
                  "dependence; docs/rve.md section 2)");
  cmd->add_option("--tolerance", o->tolerance, "Relative residual to converge to, in (0, 0.1] (default 1e-10)")
      ->check(finite_range(1e-300, 0.1, "a relative residual in (0, 0.1]"));
  cmd->add_option("--max-iterations", o->max_iterations,
                  "Newton iterations at most of each solve: the rest relaxation's and the one at the strain "
                  "(default 500)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--time-limit", o->time_limit,
                  "Wall-clock limit in seconds of the rest relaxation (all of it) and of the solve at the strain; "
                  "0: none (default 300)")
      ->check(finite_non_negative());
  cmd->add_flag("--json", o->json,
                "Print one JSON object: psi, grad, iterations, residual, seconds, converged, psi0, rest_grad, "
                "lattice_original and lattice_relaxed (lattice vectors, m), reference_strain, areal_density, certificate_valid, min_separation and d_min (in yarn diameters 2r), barrier_energy, ...");
  cmd->add_option("--certify", o->certify,
                  "Re-check the topology certificate of a state file written by --out: every configuration of its "
                  "recorded path, from the pattern's own geometry, and every straight move between them must keep "
                  "all yarn segment pairs above d_min (CCD). Exit status 3 when it does not hold")
      ->check(existing_regular_file());
  cmd->add_flag("--no-ccd", o->no_ccd,
                "Do not shorten Newton steps by collision detection (for comparison only: yarns may pass through "
                "each other; the certificate then says so)");
  cmd->add_flag("--verbose", o->verbose, "One line per Newton iteration on stderr");
  cmd->add_flag("--rest-hessian", o->rest_hessian,
                "Also measure d2Psi/ds2 at s = 0 (6 x 6, central differences of dPsi/ds from 12 small solves around "
                "the relaxed rest; what produce stores in the dataset and the training holds the networks to, "
                "yarn/rest_hessian.hpp) and say whether the rest is stable");
  cmd->callback([o] { run(*o); });
}

}  // namespace yarnhom::tools
