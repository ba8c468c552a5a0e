// Time per yarn RVE equilibrium solve (docs/benchmarks.md, "Yarn RVE solves"): for each of the
// paper's four patterns, at s_x = 0.3 and at II_x = 100/m, cold (from the relaxed rest state)
// and warm (from the solution at a strain 0.02 away: s_x = 0.28, or II_x = 98/m). The relaxed
// rest state and the neighbouring solution are computed once, outside the timing. Patterns come
// from ../shared/patterns or $YARNHOM_PATTERNS (skipped when absent); the built-in generated ones are timed too.
// The "_noccd" variants turn the collision filter off (SolveOptions::ccd = false): what the
// filter costs, apart from the barrier, which stays in the energy either way.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <tuple>
#include <memory>
#include <string>

#include "yarn/rve/energy_density.hpp"
#include "yarn/rod/generate.hpp"

using namespace yarnhom::yarn;

namespace {

struct Case {
  std::shared_ptr<RveProblem> rve;
  RveState rest, neighbour;
  Strain s;
  bool ok = true;
  std::string why;
};

std::shared_ptr<Case> make_case(const Pattern& p, int axis, double value, double step) {
  auto c = std::make_shared<Case>();
  c->rve = std::make_shared<RveProblem>(p, Material{});
  c->rest = c->rve->initial_state();
  const SolveReport r0 = solve(*c->rve, Strain::Zero(), c->rest);
  c->s = Strain::Zero();
  c->s[axis] = value;
  Strain near = Strain::Zero();
  near[axis] = value - step;
  c->neighbour = c->rest;
  const SolveReport r1 = solve(*c->rve, near, c->neighbour);
  if (!r0.converged() || !r1.converged()) {
    c->ok = false;
    c->why = "setup solve failed: " + (r0.converged() ? r1 : r0).summary();
  }
  return c;
}

void run(benchmark::State& state, std::shared_ptr<Case> c, bool warm, bool ccd) {
  if (!c->ok) {
    state.SkipWithError(c->why.c_str());
    return;
  }
  int newton = 0;
  for (auto _ : state) {
    RveState st = warm ? c->neighbour : c->rest;
    SolveOptions opt;
    opt.ccd = ccd;
    const SolveReport rep = solve(*c->rve, c->s, st, opt);
    if (!rep.converged()) {
      state.SkipWithError(("solve failed: " + rep.summary()).c_str());
      return;
    }
    newton = rep.iterations;
    benchmark::DoNotOptimize(rep.energy);
  }
  state.counters["newton_iters"] = newton;
  state.counters["unknowns"] = c->rve->num_dofs();
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  // $YARNHOM_PATTERNS, else ../shared/patterns beside the source tree this was built from.
  const char* env = std::getenv("YARNHOM_PATTERNS");
  const std::string dir = env ? std::string(env)
                              : (std::filesystem::path(__FILE__).parent_path().parent_path().parent_path() / "shared" / "patterns").string();
  std::vector<std::pair<std::string, Pattern>> patterns;
  for (const char* name : {"stockinette", "basket", "slip_stitch_honeycomb", "cartridge_belt_rib"}) {
    const std::string path = dir + "/" + name + ".pyp";
    if (std::filesystem::exists(path)) patterns.emplace_back(name, read_pyp(path));
    else std::fprintf(stderr, "bench_rve: %s not found, skipped\n", path.c_str());
  }
  for (const auto& name : builtin_pattern_names()) patterns.emplace_back("generated_" + name, builtin_pattern(name));
  for (const auto& [name, p] : patterns) {
    for (const auto& [label, axis, value, step] :
         {std::tuple<std::string, int, double, double>{"sx0.3", 0, 0.3, 0.02}, {"IIx100", 3, 100.0, 2.0}}) {
      auto c = make_case(p, axis, value, step);
      for (bool ccd : {true, false}) {
        const std::string tag = ccd ? "" : "_noccd";
        benchmark::RegisterBenchmark((name + "/" + label + "/cold" + tag).c_str(), run, c, false, ccd)->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark((name + "/" + label + "/warm" + tag).c_str(), run, c, true, ccd)->Unit(benchmark::kMillisecond);
      }
    }
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
