// Micro-benchmarks of baking and of the baked evaluator, on one thread:
//  - one value-gradient-Hessian evaluation of a baked 2D term (100 x 100 knots) at points inside
//    the box, and outside it (safeguard); target < 50 ns inside (issue 5);
//  - one value-f'-f'' evaluation of a baked 1D term (200 knots);
//  - the full material (spec 8b: 14 tables, principal curvatures) with its 6x6 Hessian;
//  - baking one 2D network at 100 x 100 and a whole 14-term model at 200 / 100 x 100.
// Tables come from random networks of the paper's size (16-32-16): the evaluator's cost does not
// depend on what the network learned. Points are drawn beforehand and cycled, so the timing is
// of the evaluation alone (including the cell lookup), with the tables in cache as in a
// simulator's inner loop over elements of one material.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "bake/bake_table.hpp"
#include "material/baked_eval.hpp"
#include "material/material.hpp"
#include "tests/common/random_net.hpp"

using namespace yarnhom;

namespace {

ModelNetwork random_network(const Term& term, unsigned seed) {
  ModelNetwork n;
  n.term = term;
  n.desc.input_dim = term.dim();
  n.params = test::random_params<float>(n.desc, seed);
  for (int i : term.indices) {
    const Range r = default_range(i);
    n.lower.push_back(r.lower);
    n.upper.push_back(r.upper);
    n.norm.center.push_back(0.5 * (r.lower + r.upper));
    n.norm.halfwidth.push_back(0.5 * (r.upper - r.lower));
  }
  return n;
}

Model random_model() {
  Model m;
  unsigned seed = 1;
  for (const Term& t : all_terms()) m.networks.push_back(random_network(t, seed++));
  return m;
}

// Points in the box widened by `extend` box widths on each side, but (if `outside`) not in it.
std::vector<Eigen::Vector2d> points_2d(const ModelNetwork& n, double extend, bool outside, int count) {
  std::mt19937 rng(5);
  std::vector<Eigen::Vector2d> p;
  while (int(p.size()) < count) {
    Eigen::Vector2d s;
    bool in = true;
    for (int i = 0; i < 2; ++i) {
      const double w = n.upper[i] - n.lower[i];
      s[i] = std::uniform_real_distribution<double>(n.lower[i] - extend * w, n.upper[i] + extend * w)(rng);
      in = in && s[i] >= n.lower[i] && s[i] <= n.upper[i];
    }
    if (!outside || !in) p.push_back(s);
  }
  return p;
}

// Evaluates f at the points in turn (their count a power of 2), one per iteration.
template <class P, class F>
void cycle_points(benchmark::State& state, const std::vector<P>& pts, F f) {
  const size_t mask = pts.size() - 1;
  size_t k = 0;
  for (auto _ : state) {
    auto r = f(pts[k++ & mask]);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations());
}

// A baked 2D table evaluated at 4096 points inside the box (extend 0) or in the band
// `extend` box widths around it (outside points only).
void baked_2d_points(benchmark::State& state, double extend, bool outside) {
  const ModelNetwork net = random_network(term_by_name("02"), 7);
  const BakedTerm t = make_baked_term(bake_network(net, 200, 100));
  cycle_points(state, points_2d(net, extend, outside, 4096), [&](const auto& s) { return eval_baked_2d(t, s); });
}

void BM_Baked2D_ValueGradHessian_Inside(benchmark::State& state) { baked_2d_points(state, 0.0, false); }
BENCHMARK(BM_Baked2D_ValueGradHessian_Inside);

void BM_Baked2D_ValueGradHessian_Outside(benchmark::State& state) { baked_2d_points(state, 0.5, true); }
BENCHMARK(BM_Baked2D_ValueGradHessian_Outside);

void BM_Baked1D_ValueDerivs(benchmark::State& state) {
  const ModelNetwork net = random_network(term_by_name("0"), 8);
  const BakedTerm t = make_baked_term(bake_network(net, 200, 100));
  std::mt19937 rng(6);
  std::vector<double> xs(4096);
  for (double& x : xs) x = std::uniform_real_distribution<double>(-0.2, 1.0)(rng);
  cycle_points(state, xs, [&](double x) { return eval_baked_1d(t, x); });
}
BENCHMARK(BM_Baked1D_ValueDerivs);

void BM_Material_ValueGradHessian(benchmark::State& state) {
  const BakedMaterial mat = make_baked_material(bake_model(random_model(), "", 200, 100, 0, false));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<Strain6> pts(1024);
  for (Strain6& s : pts) s << 0.4 + 0.6 * U(rng), 0.7 * U(rng), 0.4 + 0.6 * U(rng), 200 * U(rng), 150 * U(rng), 200 * U(rng);
  cycle_points(state, pts, [&](const Strain6& s) { return eval_material(mat, s); });
}
BENCHMARK(BM_Material_ValueGradHessian);

void BM_Bake2DTerm_100x100(benchmark::State& state) {
  const ModelNetwork net = random_network(term_by_name("02"), 7);
  for (auto _ : state) benchmark::DoNotOptimize(bake_network(net, 200, 100));
}
BENCHMARK(BM_Bake2DTerm_100x100)->Unit(benchmark::kMillisecond);

void BM_BakeModel_14Terms(benchmark::State& state) {
  const Model m = random_model();
  for (auto _ : state) benchmark::DoNotOptimize(bake_model(m, "", 200, 100, 0, false));
}
BENCHMARK(BM_BakeModel_14Terms)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
