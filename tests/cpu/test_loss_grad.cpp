// Parameter gradients of every loss term, alone and together, against central finite
// differences of the loss, in double; and the L_C stencil against the exact L_C.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/offdomain.hpp"
#include "cpu/loss_step.hpp"
#include "tests/common/random_net.hpp"

using namespace yarnhom;

namespace {

struct Problem {
  NetworkDesc desc;
  std::vector<double> params, x, y, g, xo, no, wt;  // wt empty: unweighted
  cpu::LossBatch<double> batch() const {
    cpu::LossBatch<double> b;
    b.m = int(y.size());
    b.x = x.data();
    b.y = y.data();
    b.g = g.data();
    b.k = int(xo.size()) / desc.input_dim;
    b.xo = xo.data();
    b.no = no.data();
    b.wt = wt.empty() ? nullptr : wt.data();
    return b;
  }
};

Problem make_problem(int d, int m, int k, unsigned seed) {
  Problem p;
  p.desc.input_dim = d;
  p.params = test::random_params(p.desc, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  p.x.resize(m * d);
  p.g.resize(m * d);
  p.y.resize(m);
  for (auto& v : p.x) v = u(rng);
  for (auto& v : p.g) v = u(rng);
  for (auto& v : p.y) v = u(rng);
  p.xo.resize(k * d);
  p.no.resize(k * d);
  for (int j = 0; j < k; ++j) offdomain_point<double>(d, rng_key(seed, 9), j, &p.xo[j * d], &p.no[j * d]);
  return p;
}

double rel_err(const std::vector<double>& a, const std::vector<double>& b) {
  double num = 0, den = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    num += (a[i] - b[i]) * (a[i] - b[i]);
    den += b[i] * b[i];
  }
  return std::sqrt(num / den);
}

void check_gradient(const Problem& p, const cpu::LossOptions& opt, const char* what, double h = 1e-6) {
  cpu::LossWorkspace<double> ws;
  std::vector<double> grad(p.params.size());
  auto b = p.batch();
  cpu::LossValues v = cpu::mlp_loss_grad<double>(p.desc, p.params.data(), b, opt, grad.data(), ws);
  ASSERT_GT(v.total, 1e-8) << what << ": the loss term must be active for the test to mean anything";
  std::vector<double> fd(p.params.size());
  auto q = p.params;
  for (size_t i = 0; i < q.size(); ++i) {
    const double keep = q[i];
    q[i] = keep + h;
    const double lp = cpu::mlp_loss_grad<double>(p.desc, q.data(), b, opt, nullptr, ws).total;
    q[i] = keep - h;
    const double lm = cpu::mlp_loss_grad<double>(p.desc, q.data(), b, opt, nullptr, ws).total;
    q[i] = keep;
    fd[i] = (lp - lm) / (2 * h);
  }
  EXPECT_LT(rel_err(grad, fd), 1e-6) << what << " d=" << p.desc.input_dim;
}

cpu::LossOptions only(char term) {
  cpu::LossOptions o;
  o.w = LossWeights{0, 0, 0, 0, 0};
  switch (term) {
    case 'Z': o.w.z = 1; break;
    case 'F': o.w.f = 1; break;
    case 'C': o.w.c = 1; break;
    case 'S': o.w.s = 1; break;
    case 'X': o.w.x = 1; break;
  }
  return o;
}

}  // namespace

class LossGrad : public ::testing::TestWithParam<int> {};

TEST_P(LossGrad, EachTermAloneMatchesFiniteDifferences) {
  const int d = GetParam();
  // 70 data points: two chunks, so the chunked reduction is exercised too.
  Problem p = make_problem(d, 70, 12, 5 + d);
  for (char t : {'Z', 'F', 'C', 'S', 'X'}) check_gradient(p, only(t), std::string(1, t).c_str());
}

TEST_P(LossGrad, TotalWithAllTermsMatchesFiniteDifferences) {
  const int d = GetParam();
  Problem p = make_problem(d, 9, 12, 21 + d);
  cpu::LossOptions o;
  o.w.x = 0.3;
  check_gradient(p, o, "total");
}

// Per-point weights (the polish's relative fit) on L_Z and L_F: the gradient stays exact, and the
// weights mean what they say: all 2 doubles the data losses, 0 on a point drops it.
TEST_P(LossGrad, PerPointWeightsMatchFiniteDifferencesAndScaleEachPoint) {
  const int d = GetParam();
  Problem p = make_problem(d, 70, 0, 51 + d);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.1, 5.0);
  p.wt.resize(p.y.size());
  for (auto& v : p.wt) v = u(rng);
  check_gradient(p, only('Z'), "weighted Z");
  check_gradient(p, only('F'), "weighted F");

  cpu::LossWorkspace<double> ws;
  cpu::LossOptions o;
  o.w.c = 0;
  Problem q = p;
  q.wt.clear();
  const cpu::LossValues base = cpu::mlp_loss_grad<double>(q.desc, q.params.data(), q.batch(), o, nullptr, ws);
  q.wt.assign(q.y.size(), 2.0);
  const cpu::LossValues twice = cpu::mlp_loss_grad<double>(q.desc, q.params.data(), q.batch(), o, nullptr, ws);
  EXPECT_NEAR(twice.z, 2 * base.z, 1e-12 * base.z);
  EXPECT_NEAR(twice.f, 2 * base.f, 1e-12 * base.f);
  // Weight 0 on the last point = the batch without it (the mean still divides by all m points).
  q.wt.assign(q.y.size(), 1.0);
  q.wt.back() = 0;
  const cpu::LossValues dropped = cpu::mlp_loss_grad<double>(q.desc, q.params.data(), q.batch(), o, nullptr, ws);
  Problem r = p;
  r.wt.clear();
  r.x.resize(r.x.size() - d);
  r.g.resize(r.g.size() - d);
  r.y.pop_back();
  const cpu::LossValues fewer = cpu::mlp_loss_grad<double>(r.desc, r.params.data(), r.batch(), o, nullptr, ws);
  const double m = double(p.y.size());
  EXPECT_NEAR(dropped.z * m, fewer.z * (m - 1), 1e-12);
  EXPECT_NEAR(dropped.f * m, fewer.f * (m - 1), 1e-12);
}

TEST_P(LossGrad, StencilGradientMatchesFiniteDifferences) {
  const int d = GetParam();
  Problem p = make_problem(d, 4, 0, 31 + d);
  cpu::LossOptions o = only('C');
  o.stencil_c = true;
  o.stencil_eps = 0.1;
  // The stencil divides by 2 eps^3: a larger FD step keeps rounding out of the comparison.
  check_gradient(p, o, "stencil L_C", 3e-5);
}

TEST_P(LossGrad, StencilConvergesToExactThirdDerivatives) {
  const int d = GetParam();
  Problem p = make_problem(d, 16, 0, 41 + d);
  cpu::LossWorkspace<double> ws;
  auto b = p.batch();
  const double exact = cpu::mlp_loss_grad<double>(p.desc, p.params.data(), b, only('C'), nullptr, ws).c;
  double prev = INFINITY;
  for (double eps : {0.04, 0.02, 0.01, 0.005}) {
    cpu::LossOptions o = only('C');
    o.stencil_c = true;
    o.stencil_eps = eps;
    const double err = std::abs(cpu::mlp_loss_grad<double>(p.desc, p.params.data(), b, o, nullptr, ws).c - exact);
    // Second-order stencil: halving eps divides the error by about 4.
    EXPECT_LT(err, prev / 3.0) << "eps=" << eps;
    prev = err;
  }
  EXPECT_LT(prev / exact, 1e-4);
}

TEST_P(LossGrad, ThreadCountDoesNotChangeTheResult) {
  const int d = GetParam();
  // Large enough (>= 512 points) that the chunks are spread over the threads.
  Problem p = make_problem(d, 600, 50, 51 + d);
  std::vector<float> pf(p.params.begin(), p.params.end()), xf(p.x.begin(), p.x.end()),
      yf(p.y.begin(), p.y.end()), gf(p.g.begin(), p.g.end()), xof(p.xo.begin(), p.xo.end()),
      nof(p.no.begin(), p.no.end());
  cpu::LossBatch<float> b{600, xf.data(), yf.data(), gf.data(), 50, xof.data(), nof.data()};
  cpu::LossWorkspace<float> ws;
  std::vector<float> g1(pf.size()), g2(pf.size());
  auto v1 = cpu::mlp_loss_grad<float>(p.desc, pf.data(), b, {}, g1.data(), ws, 1);
  auto v2 = cpu::mlp_loss_grad<float>(p.desc, pf.data(), b, {}, g2.data(), ws, 2);
  EXPECT_EQ(v1.total, v2.total);
  EXPECT_EQ(g1, g2);
}

INSTANTIATE_TEST_SUITE_P(Dims, LossGrad, ::testing::Values(1, 2));
