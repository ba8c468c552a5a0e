#include "yarn/rve/rve_run.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/console.hpp"
#include "core/number_list.hpp"
#include "core/scaled_eigen.hpp"
#include "core/terms.hpp"
#include "yarn/rod/load_pattern.hpp"
#include "yarn/rve/energy_density.hpp"
#include "yarn/rve/energy_map.hpp"
#include "yarn/rve/relax.hpp"
#include "yarn/rve/rest.hpp"
#include "yarn/rve/rest_hessian.hpp"
#include "yarn/rve/rve_ccd.hpp"
#include "yarn/rve/state_io.hpp"

namespace yarnhom::yarn {
namespace {

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string json_vector(const double* v, int n) {
  std::string out = "[";
  for (int k = 0; k < n; ++k) out += (k ? "," : "") + json_number(v[k]);
  return out + "]";
}

std::string json_lattice(const Eigen::Matrix2d& M) {  // rows: the two lattice vectors
  const double a[2] = {M(0, 0), M(1, 0)}, b[2] = {M(0, 1), M(1, 1)};
  return "[" + json_vector(a, 2) + "," + json_vector(b, 2) + "]";
}

// --certify: re-checks the path recorded in a state file from scratch.
int certify(const RveRunOptions& o, const RveProblem& rve) {
  const RveState st = read_state(o.certify, rve);
  const double two_r = 2 * rve.radius();
  std::printf("state       %s\n", o.certify.c_str());
  std::printf("claimed     %s\n", summary(st.certificate, two_r).c_str());
  if (st.path.empty()) {
    std::printf("re-checked  nothing: the file holds no recorded path (write it with yarnhom rve --out)\n");
    return 3;
  }
  ContactCertificate c = certify_path(rve, st.path, rve.min_separation());
  const PathPoint& last = st.path.back();
  if (!(last.s == st.anchor.s && last.u == st.u)) invalidate(c, "the recorded path does not end at the saved state");
  std::printf("re-checked  %s (%zu configurations)\n", summary(c, two_r).c_str(), st.path.size());
  return c.valid ? 0 : 3;
}

// Outputs: checked before any work, never one of the inputs, never each other.
void check_outputs(const RveRunOptions& o) {
  const std::vector<std::string> inputs = {o.pattern, o.material, o.start};
  std::vector<std::pair<std::string, std::string>> outs;
  if (!o.out.empty()) outs.push_back({prepare_output(o.out, inputs, "--out"), "--out"});
  if (!o.obj.empty()) outs.push_back({prepare_output(o.obj, inputs, "--obj"), "--obj"});
  if (!o.pattern_out.empty()) outs.push_back({prepare_output(o.pattern_out, inputs, "--pattern-out"), "--pattern-out"});
  if (!o.energy_map.empty()) outs.push_back({prepare_output(o.energy_map, inputs, "--energy-map"), "--energy-map"});
  for (size_t i = 0; i < outs.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (std::filesystem::weakly_canonical(outs[i].first) == std::filesystem::weakly_canonical(outs[j].first))
        throw std::invalid_argument(outs[j].second + " and " + outs[i].second + " name the same file " + outs[i].first);
}

Strain parse_strain(const std::string& text) {
  const std::vector<double> sv = parse_numbers(text, "--strain");
  if (sv.size() != 6)
    throw std::invalid_argument("--strain: expected 6 comma-separated values (s_x,s_a,s_y,II_x,II_a,II_y), got " +
                                std::to_string(sv.size()));
  Strain s = Eigen::Map<const Strain>(sv.data());
  for (int k = 0; k < 6; ++k)
    if (std::string rule = strain_domain_violation(k, s[k]); !rule.empty()) throw std::invalid_argument("--strain: " + rule);
  return s;
}

// Everything the report prints.
struct RveOutcome {
  Pattern pattern;
  Material mat;
  Strain s;
  std::unique_ptr<RveProblem> rve;
  RveState st;
  RestReport rest;
  bool relaxed = false;
  DensityResult at_rest, r;
  RestHessian rh;
};

// The reference: the pattern relaxed at rest, its period included (s = 0 is then the
// stress-free tile; docs/rve.md section 6), or the reference a given state was solved in.
// With --out the whole path (from the pattern's own geometry) is recorded in the state file,
// for --certify.
void reference_state(const RveRunOptions& o, const Pattern& base, int nx, int ny, const SolveOptions& opt, RveOutcome& x) {
  if (!o.start.empty()) {
    if (!o.pattern_out.empty()) throw std::invalid_argument("--pattern-out needs the rest relaxation: drop --start");
    x.rve = std::make_unique<RveProblem>(x.pattern, x.mat, RveOptions{}, read_state_reference(o.start));
    x.st = read_state(o.start, *x.rve);
    if (o.out.empty()) x.st.path.clear();
    return;
  }
  RestOptions ro;
  ro.free_period = !o.fixed_period;
  ro.solve = opt;  // --max-iterations and --time-limit bound the rest relaxation too
  ro.first_max_iterations = opt.max_iterations;
  ro.max_seconds = o.time_limit;
  ro.verbose = o.verbose;
  ro.record_path = !o.out.empty();
  // A tiling is the same material on a larger RVE: the pattern's relaxed rest repeated.
  RestTile tile = repeat_rest(base, relax_tile(base, x.mat, ro), nx, ny);
  x.rve = std::make_unique<RveProblem>(std::move(tile.rve));
  x.st = std::move(tile.state);
  x.rest = tile.report;
  x.relaxed = true;
  if (o.pattern_out.empty()) return;
  if (x.rve->reference()(0, 1) != 0.0)
    throw std::invalid_argument("--pattern-out: the relaxed tile of '" + x.pattern.name +
                                "' is sheared (s_a = " + std::to_string(x.rest.strain[1]) +
                                "), which a .pyp tile (px x py) cannot hold; add --fixed-period");
  write_pyp(o.pattern_out, pattern_at(*x.rve, x.st));
}

void print_json(const RveRunOptions& o, const RveOutcome& x) {
  const RveProblem& rve = *x.rve;
  const DensityResult& r = x.r;
  const Eigen::Matrix2d L0 = Eigen::Vector2d(x.pattern.px, x.pattern.py).asDiagonal(), L = rve.lattice();
  std::string g;
  for (int k = 0; k < 6; ++k) g += (k ? "," : "") + json_number(r.grad[k]);
  std::printf(
      "{\"pattern\":\"%s\",\"psi\":%s,\"grad\":[%s],\"iterations\":%d,\"residual\":%s,\"seconds\":%s,"
      "\"converged\":%s,\"status\":\"%s\",\"energy\":%s,\"rest_iterations\":%d,"
      "\"rest_period_updates\":%d,\"psi0\":%s,\"rest_grad\":%s,\"lattice_original\":%s,"
      "\"lattice_relaxed\":%s,\"reference_strain\":%s,\"areal_density\":%s,\"certificate_valid\":%s,"
      "\"min_separation\":%s,\"d_min\":%s,\"barrier_energy\":%s%s}\n",
      x.pattern.name.c_str(), json_number(r.psi).c_str(), g.c_str(), r.report.iterations,
      json_number(r.report.residual).c_str(), json_number(r.report.seconds).c_str(),
      r.report.converged() ? "true" : "false", to_string(r.report.status), json_number(r.report.energy).c_str(),
      x.relaxed ? x.rest.inner_iterations : 0, x.relaxed ? x.rest.iterations : 0, json_number(x.at_rest.psi).c_str(),
      json_vector(x.at_rest.grad.data(), 6).c_str(), json_lattice(L0).c_str(), json_lattice(L).c_str(),
      json_vector(in_plane_strain(rve.reference()).data(), 3).c_str(), json_number(areal_density(rve)).c_str(),
      x.st.certificate.valid ? "true" : "false", json_number(x.st.certificate.min_distance / (2 * rve.radius())).c_str(),
      json_number(rve.min_separation() / (2 * rve.radius())).c_str(), json_number(r.parts.barrier).c_str(),
      o.rest_hessian ? (",\"rest_hessian\":" + json_vector(x.rh.H.data(), 36) +
                        ",\"rest_hessian_smallest_scaled_eigenvalue\":" + json_number(scaled_eigen(x.rh.H).values[0]) +
                        ",\"rest_hessian_asymmetry\":" + json_number(x.rh.asymmetry)).c_str()
                     : "");
}

void print_rest_hessian(const RestHessian& rh) {
  const ScaledEigen se = scaled_eigen(rh.H);
  std::printf("rest Hessian d2Psi/ds2 at s = 0 (rows and columns s_x s_a s_y II_x II_a II_y; %d solves, steps %.3g "
              "and %.3g 1/m, asymmetry %.1e):\n", rh.solves, rh.step[0], rh.step[3], rh.asymmetry);
  for (int i = 0; i < 6; ++i) {
    std::printf("           ");
    for (int j = 0; j < 6; ++j) std::printf(" %12.5g", rh.H(i, j));
    std::printf("\n");
  }
  std::printf("            %s: smallest scaled eigenvalue %.3g\n", se.stable() ? "stable" : "UNSTABLE", se.values[0]);
}

void print_text(const RveRunOptions& o, const RveOutcome& x) {
  const RveProblem& rve = *x.rve;
  const DensityResult& r = x.r;
  const Strain& s = x.s;
  const Eigen::Matrix2d L0 = Eigen::Vector2d(x.pattern.px, x.pattern.py).asDiagonal(), L = rve.lattice();
  std::printf("pattern     %s (%d vertices, %zu yarns, %d unknowns)\n", x.pattern.name.c_str(), x.pattern.size(),
              rve.topo().yarns.size(), rve.num_dofs());
  if (x.relaxed) std::printf("rest        %s\n", x.rest.summary().c_str());
  std::printf("period      pattern (%.6g, 0) (0, %.6g) m; reference (%.6g, %.6g) (%.6g, %.6g) m%s\n", L0(0, 0),
              L0(1, 1), L(0, 0), L(1, 0), L(0, 1), L(1, 1),
              rve.reference().isIdentity(0.0) ? " (the pattern's: pre-stressed)" : " (relaxed: stress free)");
  std::printf("at rest     Psi0 %.10g J/m^2, dPsi/ds %.4g %.4g %.4g, dPsi/dII %.6g %.6g %.6g J/m\n", x.at_rest.psi,
              x.at_rest.grad[0], x.at_rest.grad[1], x.at_rest.grad[2], x.at_rest.grad[3], x.at_rest.grad[4],
              x.at_rest.grad[5]);
  if (o.rest_hessian) print_rest_hessian(x.rh);
  std::printf("density     %.6g kg/m^2 (yarn %.6g kg/m^3)\n", areal_density(rve), x.mat.density);
  std::printf("strain      s_x %g  s_a %g  s_y %g  II_x %g  II_a %g  II_y %g (1/m)\n", s[0], s[1], s[2], s[3], s[4], s[5]);
  std::printf("solve       %s\n", r.report.summary().c_str());
  std::printf("Psi         %.10g J/m^2\n", r.psi);
  std::printf("dPsi/ds     %.8g %.8g %.8g %.8g %.8g %.8g\n", r.grad[0], r.grad[1], r.grad[2], r.grad[3], r.grad[4], r.grad[5]);
  std::printf("energy      stretch %.4g  bend %.4g  twist %.4g  contact %.4g  barrier %.4g J\n", r.parts.stretch,
              r.parts.bend, r.parts.twist, r.parts.contact, r.parts.barrier);
  std::printf("topology    %s\n", summary(x.st.certificate, 2 * rve.radius()).c_str());
  if (!o.out.empty()) std::printf("state       %s\n", o.out.c_str());
  if (!o.obj.empty()) std::printf("mesh        %s\n", o.obj.c_str());
  if (!o.energy_map.empty()) std::printf("energy map  %s\n", o.energy_map.c_str());
}

int exit_status(const RveOutcome& x) {
  if (!x.r.report.converged()) {
    std::fprintf(stderr, "yarnhom: error: the RVE solve did not converge: %s\n", x.r.report.summary().c_str());
    if (x.r.report.status == SolveStatus::kInfeasibleStart)
      std::fprintf(stderr, "yarnhom: the strain is too far from the start for one step: solve at an intermediate strain "
                           "first (--out), then --start from it\n");
    return 2;
  }
  if (!x.st.certificate.valid) {
    std::fprintf(stderr, "yarnhom: error: the solution is not certified to have the rest state's topology: %s\n",
                 summary(x.st.certificate, 2 * x.rve->radius()).c_str());
    return 3;
  }
  return 0;
}

}  // namespace

int run_rve(const RveRunOptions& o) {
  check_outputs(o);
  RveOutcome x;
  x.s = parse_strain(o.strain);
  x.mat = o.material.empty() ? Material{} : load_material(o.material);
  const auto [nx, ny] = parse_tiles(o.tile, "--tile");
  const Pattern base = load_pattern(o.pattern);
  x.pattern = nx * ny > 1 ? tile(base, nx, ny) : base;
  if (!o.certify.empty()) {
    const RveProblem rve(x.pattern, x.mat, RveOptions{}, read_state_reference(o.certify));
    return certify(o, rve);
  }
  SolveOptions opt;
  opt.ccd = !o.no_ccd;
  opt.tolerance = o.tolerance;
  opt.max_iterations = o.max_iterations;
  opt.max_seconds = o.time_limit;
  opt.verbose = o.verbose;
  reference_state(o, base, nx, ny, opt, x);
  x.at_rest = evaluate_density(*x.rve, Strain::Zero(), x.st);
  if (o.rest_hessian) {
    if (!x.relaxed) throw std::invalid_argument("--rest-hessian needs the rest relaxation: drop --start");
    x.rh = rest_hessian(*x.rve, x.st, opt);
    if (!x.rh.ok) throw std::runtime_error("--rest-hessian: " + x.rh.failure);
  }
  x.r = energy_density(*x.rve, x.s, x.st, opt);
  if (!o.out.empty()) write_state(o.out, *x.rve, x.s, x.st, x.r);
  if (!o.obj.empty()) write_obj(o.obj, *x.rve, x.s, x.st);
  if (!o.energy_map.empty()) write_energy_map(o.energy_map, *x.rve, energy_map(*x.rve, x.s, x.st));
  if (o.json)
    print_json(o, x);
  else
    print_text(o, x);
  return exit_status(x);
}

}  // namespace yarnhom::yarn
