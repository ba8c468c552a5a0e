// Micro-benchmarks of the continuum simulator's parts (docs/benchmarks.md, "Continuum
// simulator"): the full material (14 baked tables, principal-curvature mixing), one element's
// strain with its derivatives, the PSD projection of an element Hessian, the whole assembly of
// a sheet's energy, gradient and projected Hessian, and one sparse factorization, at the three
// mesh sizes of the study (1k, 4k, 16k triangles). The material is a polynomial baked into
// tables of the production resolution (200 / 100 x 100): the same work per evaluation as a
// trained model's tables. The sheet is in a draped-like state (wrinkled, compressed, bent).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <random>
#include <omp.h>
#include <unistd.h>

#include <cstdlib>

#include "bake/bake_table.hpp"
#include "material/material.hpp"
#include "core/jet_layout.hpp"
#include "numerics/blas_threads.hpp"
#include "numerics/contact_pairs.hpp"
#include "sim/contact.hpp"
#include "sim/contact_broad_phase.hpp"
#include "sim/dof_map.hpp"
#include "sim/hessian_pattern.hpp"
#include "numerics/sparse_cholesky.hpp"
#include "sim/newton.hpp"
#include "numerics/psd_projection.hpp"
#include "sim/rectangle.hpp"
#include "sim/shell_energy.hpp"
#include "sim/shell_strain.hpp"
#include "numerics/block_jacobi_pcg.hpp"
#include "tests/common/pcg_test_system.hpp"

using namespace yarnhom;
using namespace yarnhom::numerics;
using namespace yarnhom::sim;

namespace {

// Every term a smooth polynomial in scaled strains X = s / c (c = 1 in-plane, 100 /m bending):
// a (X^2 + 0.3 X^3) in 1D, a (X Y + 0.2 X^2 Y^2) in 2D, with derivatives to order 2.
TermFunction poly_term(const Term& t, double a) {
  const int d = t.dim();
  const double cx = t.indices[0] >= 3 ? 100 : 1, cy = d == 2 && t.indices[1] >= 3 ? 100 : 1;
  return [d, a, cx, cy](const double* s, int n, int order) {
    const int C = jet_channels(d, order);
    std::vector<double> out(size_t(C) * n, 0.0);
    for (int q = 0; q < n; ++q) {
      const double X = s[q * d] / cx, Y = d == 2 ? s[q * d + 1] / cy : 0;
      if (d == 1) {
        out[q] = a * (X * X + 0.3 * X * X * X);
        if (order >= 1) out[n + q] = a * (2 * X + 0.9 * X * X) / cx;
        if (order >= 2) out[2 * n + q] = a * (2 + 1.8 * X) / (cx * cx);
      } else {
        out[q] = a * (X * Y + 0.2 * X * X * Y * Y);
        if (order >= 1) {
          out[n + q] = a * (Y + 0.4 * X * Y * Y) / cx;
          out[2 * n + q] = a * (X + 0.4 * X * X * Y) / cy;
        }
        if (order >= 2) {
          out[3 * n + q] = a * 0.4 * Y * Y / (cx * cx);
          out[4 * n + q] = a * (1 + 0.8 * X * Y) / (cx * cy);
          out[5 * n + q] = a * 0.4 * X * X / (cy * cy);
        }
      }
    }
    return out;
  };
}

const BakedMaterial& material() {
  static const BakedMaterial mat = [] {
    BakedModel m;
    for (const Term& t : all_terms()) {
      std::vector<double> lo, hi;
      for (int i : t.indices) {
        const Range r = default_range(i, 200, 200);
        lo.push_back(r.lower);
        hi.push_back(r.upper);
      }
      m.tables.push_back(bake_function(t, lo, hi, std::vector<int>(t.dim(), t.dim() == 1 ? 200 : 100),
                                       poly_term(t, t.dim() == 1 ? 5.0 : 1.0)));
    }
    return make_baked_material(m);
  }();
  return mat;
}

// A draped-like state of an n x n sheet of 0.5 m: compressed, wrinkled, bent over a dome.
Eigen::VectorXd draped(const Mesh& m) {
  Eigen::VectorXd x(3 * m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double u = m.rest(v, 0) - 0.25, w = m.rest(v, 1) - 0.25;
    const double r2 = u * u + w * w;
    x.segment<3>(3 * v) << 0.97 * u + 0.004 * std::sin(60 * w), 0.98 * w, 0.15 - 2 * r2 + 0.003 * std::sin(80 * u + 30 * w);
  }
  return x;
}

// Quads per side for about 1k, 4k and 16k triangles.
int side(int triangles) { return int(std::lround(std::sqrt(triangles / 2.0))); }

void BM_MaterialEval(benchmark::State& state) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-0.2, 0.5), B(-150, 150);
  std::vector<Strain6> pts(1024);
  for (auto& s : pts) s << U(rng), 0.5 * U(rng), U(rng), B(rng), 0.3 * B(rng), B(rng);
  size_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(eval_material(material(), pts[k++ & 1023]));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_MaterialEval);

void BM_ElementStrainDerivatives(benchmark::State& state) {
  const Mesh m = make_rectangle(0.5, 0.5, 20, 20);
  const auto rest = make_element_rests(m);
  const Eigen::VectorXd x = draped(m);
  const int t = 2 * (10 * 20 + 10);
  bool fl[3];
  Vec18 q;
  for (int i = 0; i < 3; ++i) {
    q.segment<3>(3 * i) = x.segment<3>(3 * m.tris(t, i));
    fl[i] = true;
    q.segment<3>(9 + 3 * i) = x.segment<3>(3 * m.flaps(t, i));
  }
  Strain6 lam;
  lam << 1, 0.2, 0.8, 1e-3, 2e-4, 1e-3;
  for (auto _ : state) {
    Jac6x18 J;
    Mat18 H;
    benchmark::DoNotOptimize(shell_strain(q, rest[t], fl, &J));
    shell_strain(q, rest[t], fl, nullptr, &lam, &H);
    benchmark::DoNotOptimize(H);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ElementStrainDerivatives);

void BM_ElementPsdProjection(benchmark::State& state) {
  std::mt19937 rng(2);
  std::normal_distribution<double> N(0, 1);
  std::vector<Mat18> Hs(64);
  for (auto& H : Hs) {
    Eigen::Matrix<double, 18, 12> A;
    for (int i = 0; i < 18; ++i)
      for (int j = 0; j < 12; ++j) A(i, j) = N(rng);
    Eigen::Matrix<double, 18, 2> B;
    for (int i = 0; i < 18; ++i)
      for (int j = 0; j < 2; ++j) B(i, j) = N(rng);
    H = A * A.transpose() - 0.1 * B * B.transpose();  // mostly positive, a few negative modes
  }
  size_t k = 0;
  for (auto _ : state) {
    Mat18 H = Hs[k++ & 63];
    benchmark::DoNotOptimize(numerics::project_psd(H));
    benchmark::DoNotOptimize(H);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ElementPsdProjection);

// A draped square sheet of about `triangles` triangles with the benchmark material, its DOFs
// (all free) and Hessian pattern.
struct Sheet {
  explicit Sheet(int triangles)
      : m(make_rectangle(0.5, 0.5, side(triangles), side(triangles))), rest(make_element_rests(m)), x(draped(m)),
        D(make_dof_map(m.num_vertices(), {})), pat(make_hessian_pattern(m, D)) {}
  Mesh m;
  std::vector<ElementRest> rest;
  Eigen::VectorXd x;
  DofMap D;
  HessianPattern pat;
  MaterialFn psi = [](const Strain6& s) { return eval_material(material(), s); };
};

// Energy + gradient + PSD Hessian of the whole sheet (all threads); range(1): the Hessian model,
// 0 ProjectedElement (18x18 eigenproblems), 1 Split (6x6; sim/hessian_model.hpp).
void BM_Assembly(benchmark::State& state) {
  const HessianModel model = state.range(1) ? HessianModel::Split : HessianModel::ProjectedElement;
  Sheet S(int(state.range(0)));
  Eigen::SparseMatrix<double> H = S.pat.matrix;
  ShellTimings tm;
  for (auto _ : state) {
    std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(S.x.size());
    benchmark::DoNotOptimize(shell_energy_derivatives(S.m, S.rest, S.psi, S.x, g, &S.pat, H.valuePtr(), &tm, model));
  }
  state.counters["triangles"] = S.m.num_triangles();
  state.counters["projected_%"] = 100.0 * tm.projected / std::max<long>(1, tm.elements);
  state.SetLabel(hessian_model_name(model));
}
BENCHMARK(BM_Assembly)
    ->Args({1000, 0})->Args({4000, 0})->Args({16000, 0})
    ->Args({1000, 1})->Args({4000, 1})->Args({16000, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// One numeric factorization of the Newton matrix (mass term added so that it is definite);
// range(1): 0 LDL^T, 1 CHOLMOD; range(2): CHOLMOD's ordering, 0 its default (AMD here), 1 METIS,
// 2 nested dissection (numerics/sparse_cholesky.hpp).
void BM_Factorize(benchmark::State& state) {
  Sheet S(int(state.range(0)));
  const Mesh& m = S.m;
  const HessianPattern& pat = S.pat;
  Eigen::SparseMatrix<double> H = pat.matrix;
  Eigen::VectorXd g = Eigen::VectorXd::Zero(S.x.size());
  shell_energy_derivatives(m, S.rest, S.psi, S.x, g, &pat, H.valuePtr());
  const double mass = 0.3 * 0.25 / m.num_vertices() * 900;  // m / h^2 at h = 1/30
  for (int f = 0; f < S.D.num_free(); ++f) add_vertex_hessian(pat, f, mass * Eigen::Matrix3d::Identity(), H.valuePtr());
  const Ordering ordering = state.range(2) == 1 ? Ordering::Metis : state.range(2) == 2 ? Ordering::NestedDissection
                                                                                          : Ordering::Default;
  LinearSolver solver(state.range(1) ? SolverKind::Cholmod : SolverKind::Ldlt, ordering);
  solver.factorize(H);  // analysis outside the timing
  for (auto _ : state) benchmark::DoNotOptimize(solver.factorize(H));
  state.counters["unknowns"] = H.rows();
  state.counters["nnz_L"] = solver.factor_nonzeros();
  state.counters["GFlop"] = solver.factor_flops() * 1e-9;
  const char* names[] = {"", ", METIS", ", nested dissection"};
  state.SetLabel(std::string(solver.name()) + names[state.range(2)] + ", " + blas_description());
}
BENCHMARK(BM_Factorize)
    ->Args({1000, 0, 0})->Args({4000, 0, 0})->Args({16000, 0, 0})
    ->Args({1000, 1, 0})->Args({4000, 1, 0})->Args({16000, 1, 0})
    ->Args({16000, 1, 1})->Args({16000, 1, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// The contact broad phase's pair search (numerics::box_pairs: the grid's counting sort, then
// the queries in chunks): the draped sheet's edge boxes, inflated by d_hat / 2 = 0.5 mm, against
// themselves; range(1) OpenMP threads (the self-collision region of a step builds this and the
// triangle-vertex search twice).
void BM_BoxPairs(benchmark::State& state) {
  Sheet S(int(state.range(0)));
  const std::vector<Eigen::Vector2i> edges = cloth_edges(S.m);
  std::vector<Box3> boxes(edges.size());
  for (size_t e = 0; e < edges.size(); ++e) boxes[e] = move_box(edges[e], 2, S.x, S.x, 5e-4);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(int(state.range(1)));
  size_t pairs = 0;
  for (auto _ : state) {
    const auto p = box_pairs(boxes, boxes, true);
    pairs = p.size();
    benchmark::DoNotOptimize(p.data());
  }
  omp_set_num_threads(saved);
  state.counters["boxes"] = double(boxes.size());
  state.counters["pairs"] = double(pairs);
}
BENCHMARK(BM_BoxPairs)->Args({16000, 1})->Args({16000, 2})->Args({16000, 16})->Unit(benchmark::kMillisecond)->UseRealTime();

// One solve of the block-Jacobi PCG's CPU twin (numerics/block_jacobi_pcg.hpp) to the one-solve
// step's relative residual 1e-3, on the shell's stencil (tests/common/pcg_test_system.hpp:
// range(0) vertices a side, 121: a T-shirt's 43,923 unknowns, mass 1e-3 against stiffness 1: 249
// iterations, as the T-shirt's 246-257; one thread below 100,000 unknowns). The GPU twin's is
// BM_CudaBlockJacobiPcg (bench_cuda.cpp), on the same system.
void BM_BlockJacobiPcg(benchmark::State& state) {
  const Eigen::SparseMatrix<double> L = test::pcg_shell_system(int(state.range(0)), 0.001, 1.0);
  BlockJacobiBuilder builder;
  BlockCsr A;
  builder.build(L, A);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.n, -1.0, 1.0).array().sin();
  Eigen::VectorXd x(A.n);
  BlockPcgResult r;
  double seconds = 0;
  long iterations = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    r = block_jacobi_pcg(A, b.data(), x.data(), 1e-3, 100000);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    iterations += r.iterations;
  }
  state.counters["unknowns"] = A.n;
  state.counters["iterations"] = r.iterations;
  state.counters["us_per_iteration"] = iterations > 0 ? 1e6 * seconds / double(iterations) : 0.0;
}
BENCHMARK(BM_BlockJacobiPcg)->Arg(121)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

// As `yarnhom` does (tools/cli/main.cpp): on a CPU OpenBLAS does not know, start again with the
// kernels the CPU supports, so that the factorization is timed as the simulator runs it.
int main(int argc, char** argv) {
  if (const char* kernels = blas_kernels_to_request()) {
    setenv("OPENBLAS_CORETYPE", kernels, 1);
    execv("/proc/self/exe", argv);  // returns only on failure: carry on with the kernels we have
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
