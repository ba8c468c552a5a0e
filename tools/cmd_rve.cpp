// yarnhom rve: the yarn RVE of a pattern at one macroscopic strain: Psi, dPsi/ds, the solver's
// report; optionally the equilibrium state (HDF5) and a tube mesh of the yarns (OBJ).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "tools/cli_util.hpp"
#include "tools/commands.hpp"
#include "yarn/energy_density.hpp"
#include "yarn/generate.hpp"
#include "yarn/relax.hpp"
#include "yarn/state_io.hpp"

namespace yarnhom::tools {
namespace {

struct RveOpts {
  std::string pattern, strain = "0,0,0,0,0,0", material, out, obj, start, pattern_out;
  bool json = false, verbose = false;
  double tolerance = 1e-10;
  int max_iterations = 200;
};

yarn::Pattern load_pattern(const std::string& what) {
  if (std::filesystem::exists(what)) return yarn::read_pyp(what);
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

void run(const RveOpts& o) {
  const std::vector<double> sv = parse_numbers(o.strain, "--strain");
  if (sv.size() != 6)
    throw std::invalid_argument("--strain: expected 6 comma-separated values (s_x,s_a,s_y,II_x,II_a,II_y), got " +
                                std::to_string(sv.size()));
  yarn::Strain s = Eigen::Map<const yarn::Strain>(sv.data());
  if (!(s[0] > -1 && s[2] > -1 && std::abs(s[1]) < 1))
    throw std::invalid_argument("--strain: need s_x > -1, s_y > -1 and |s_a| < 1");
  const yarn::Material mat = o.material.empty() ? yarn::Material{} : yarn::read_material(o.material);
  const yarn::RveProblem rve(load_pattern(o.pattern), mat);
  yarn::SolveOptions opt;
  opt.tolerance = o.tolerance;
  opt.max_iterations = o.max_iterations;
  opt.verbose = o.verbose;

  // Start: a given state, else the pattern relaxed at rest (the paper's patterns store rest
  // lengths, curvatures and twists that differ from their geometry: never measure unrelaxed).
  yarn::RveState st = rve.initial_state();
  yarn::SolveReport rest;
  bool relaxed = false;
  if (!o.start.empty()) {
    if (!o.pattern_out.empty()) throw std::invalid_argument("--pattern-out needs the rest relaxation: drop --start");
    st = yarn::read_state(o.start, rve);
  } else {
    yarn::SolveOptions rest_opt = opt;
    rest_opt.max_iterations = std::max(opt.max_iterations, 200);  // --max-iterations is for the strain
    rest = yarn::solve(rve, yarn::Strain::Zero(), st, rest_opt);
    relaxed = true;
    if (!rest.converged()) throw std::runtime_error("relaxing '" + rve.pattern().name + "' at rest: " + rest.summary());
    if (!o.pattern_out.empty()) yarn::write_pyp(o.pattern_out, yarn::pattern_at(rve, st));
  }
  const yarn::DensityResult r = yarn::energy_density(rve, s, st, opt);
  if (!o.out.empty()) yarn::write_state(o.out, rve, s, st, r);
  if (!o.obj.empty()) yarn::write_obj(o.obj, rve, s, st);

  if (o.json) {
    std::string g;
    for (int k = 0; k < 6; ++k) g += (k ? "," : "") + json_number(r.grad[k]);
    std::printf(
        "{\"pattern\":\"%s\",\"psi\":%s,\"grad\":[%s],\"iterations\":%d,\"residual\":%s,\"seconds\":%s,"
        "\"converged\":%s,\"status\":\"%s\",\"energy\":%s,\"rest_iterations\":%d}\n",
        rve.pattern().name.c_str(), json_number(r.psi).c_str(), g.c_str(), r.report.iterations,
        json_number(r.report.residual).c_str(), json_number(r.report.seconds).c_str(),
        r.report.converged() ? "true" : "false", yarn::to_string(r.report.status),
        json_number(r.report.energy).c_str(), relaxed ? rest.iterations : 0);
  } else {
    std::printf("pattern     %s (%d vertices, %zu yarns, %d unknowns)\n", rve.pattern().name.c_str(),
                rve.pattern().size(), rve.topo().yarns.size(), rve.num_dofs());
    if (relaxed) std::printf("rest        %s\n", rest.summary().c_str());
    std::printf("strain      s_x %g  s_a %g  s_y %g  II_x %g  II_a %g  II_y %g (1/m)\n", s[0], s[1], s[2], s[3], s[4], s[5]);
    std::printf("solve       %s\n", r.report.summary().c_str());
    std::printf("Psi         %.10g J/m^2\n", r.psi);
    std::printf("dPsi/ds     %.8g %.8g %.8g %.8g %.8g %.8g\n", r.grad[0], r.grad[1], r.grad[2], r.grad[3], r.grad[4], r.grad[5]);
    std::printf("energy      stretch %.4g  bend %.4g  twist %.4g  contact %.4g J\n", r.parts.stretch,
                r.parts.bend, r.parts.twist, r.parts.contact);
    if (!o.out.empty()) std::printf("state       %s\n", o.out.c_str());
    if (!o.obj.empty()) std::printf("mesh        %s\n", o.obj.c_str());
  }
  if (!r.report.converged()) {
    std::fprintf(stderr, "yarnhom: error: the RVE solve did not converge: %s\n", r.report.summary().c_str());
    throw ExitCode{2};
  }
}

}  // namespace

void register_rve(CLI::App& app) {
  auto o = std::make_shared<RveOpts>();
  auto* cmd = app.add_subcommand(
      "rve",
      "Solve the periodic yarn RVE of a pattern at one macroscopic strain (docs/rve.md): relaxes "
      "the pattern at rest, then minimizes the energy at the strain with Newton's method. Prints "
      "Psi (J/m^2), dPsi/ds (envelope theorem), iterations, final residual and time. Exit status "
      "2 when the solve does not converge.");
  cmd->add_option("PATTERN", o->pattern, "A .pyp file, or a built-in pattern: basket, plain, stockinette")->required();
  cmd->add_option("--strain", o->strain, "s_x,s_a,s_y,II_x,II_a,II_y (II in 1/m; default 0,0,0,0,0,0)");
  cmd->add_option("--material", o->material, "Material file: 'key = value' lines (docs/yarn_material.md)")->check(CLI::ExistingFile);
  cmd->add_option("--out", o->out, "Write the equilibrium state (HDF5)");
  cmd->add_option("--obj", o->obj, "Write a tube mesh of the yarns (OBJ)");
  cmd->add_option("--pattern-out", o->pattern_out,
                  "Write the pattern relaxed at rest as .pyp (its geometry is then an equilibrium)");
  cmd->add_option("--start", o->start, "Start from this state file (warm start) instead of the relaxed rest state")->check(CLI::ExistingFile);
  cmd->add_option("--tolerance", o->tolerance, "Relative residual to converge to (default 1e-10)");
  cmd->add_option("--max-iterations", o->max_iterations, "Newton iterations at most (default 200)");
  cmd->add_flag("--json", o->json, "Print one JSON object: psi, grad, iterations, residual, seconds, converged, ...");
  cmd->add_flag("--verbose", o->verbose, "One line per Newton iteration on stderr");
  cmd->callback([o] { run(*o); });
}

}  // namespace yarnhom::tools
