// yarn/rve/rve.cpp: the energy, gradient, Hessian and dE/ds of a large RVE are the same bits at
// any thread count (fixed chunks added in a fixed order), so that produce on MPI ranks of one
// thread each writes the dataset of a many-thread run (docs/produce.md, "On a cluster").
#include <gtest/gtest.h>
#include <omp.h>

#include <cstring>
#include <vector>

#include "yarn/rod/generate.hpp"
#include "yarn/rod/material.hpp"
#include "yarn/rve/rve.hpp"

using namespace yarnhom::yarn;

namespace {

struct Eval {
  double e = 0;
  Eigen::VectorXd g;
  std::vector<Eigen::Triplet<double>> h;
  Strain d = Strain::Zero();
};

Eval evaluate_on(int threads, const RveProblem& rve, const Strain& s, const RveState& st) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  Eval r;
  r.e = rve.evaluate(s, st, &r.g, &r.h, nullptr, &r.d);
  omp_set_num_threads(saved);
  return r;
}

bool same(const Eval& a, const Eval& b) {
  if (std::memcmp(&a.e, &b.e, sizeof a.e) || a.g.size() != b.g.size() || a.h.size() != b.h.size()) return false;
  if (std::memcmp(a.g.data(), b.g.data(), a.g.size() * sizeof(double))) return false;
  if (std::memcmp(a.d.data(), b.d.data(), 6 * sizeof(double))) return false;
  for (size_t i = 0; i < a.h.size(); ++i)
    if (a.h[i].row() != b.h[i].row() || a.h[i].col() != b.h[i].col() ||
        std::memcmp(&a.h[i].value(), &b.h[i].value(), sizeof(double)))
      return false;
  return true;
}

}  // namespace

TEST(RveThreads, LargeTileEvaluatesToTheSameBitsOnAnyThreadCount) {
  StockinetteParams prm;
  prm.samples = 160;  // past the 150 vertices from which the sums run in chunks
  prm.rest_from_shape = true;
  const RveProblem rve(generate_stockinette(prm), Material{});
  RveState st = rve.initial_state();
  // Off the rest: a strain with stretch, shear and bending, and fluctuations that bring
  // segments into contact range.
  Strain s;
  s << 0.05, 0.1, -0.05, 30, 5, -20;
  for (size_t v = 0; v < st.u.size(); ++v) st.u[v] += 1e-5 * Eigen::Vector3d(std::sin(v), std::cos(3.0 * v), std::sin(7.0 * v));
  const Eval one = evaluate_on(1, rve, s, st);
  ASSERT_GT(one.h.size(), 0u);
  for (int t : {2, 3, 8}) EXPECT_TRUE(same(one, evaluate_on(t, rve, s, st))) << t << " threads";
  // And inside an enclosing parallel region (the producer's sectors), serially.
  Eval nested;
#pragma omp parallel num_threads(2)
  {
#pragma omp single
    nested = evaluate_on(omp_get_max_threads(), rve, s, st);
  }
  EXPECT_TRUE(same(one, nested));
}
