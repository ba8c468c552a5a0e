// Input derivatives of the jet forward pass against central finite differences of the value,
// in double, for d = 1 and 2, random weights, several points.
#include <gtest/gtest.h>

#include <random>

#include "cpu/mlp_jet.hpp"
#include "tests/common/random_net.hpp"

using namespace yarnhom;

namespace {

// Value of the network at one point.
double value_at(const NetworkDesc& desc, const std::vector<double>& p, const double* x) {
  cpu::JetWorkspace<double> ws;
  double out;
  cpu::mlp_jet_forward<double>(desc, p.data(), x, 1, 0, &out, ws);
  return out;
}

// All jet channels at one point by finite differences of the value: nested central
// differences, step h per order (errors O(h^2) at each level).
std::vector<double> fd_jet(const NetworkDesc& desc, const std::vector<double>& p, const double* x) {
  const int d = desc.input_dim;
  auto f = [&](double dx, double dy) {
    double y[2] = {x[0] + dx, d == 2 ? x[1] + dy : 0.0};
    return value_at(desc, p, y);
  };
  auto shift = [&](int i, double h) { return std::pair<double, double>{i == 0 ? h : 0, i == 1 ? h : 0}; };
  std::vector<double> out(jet_channels(d, 3));
  out[0] = f(0, 0);
  const double h1 = 1e-5, h2 = 1e-4, h3 = 2e-3;
  for (int i = 0; i < d; ++i) {
    auto [a, b] = shift(i, h1);
    out[1 + i] = (f(a, b) - f(-a, -b)) / (2 * h1);
  }
  for (int q = 0; q < jet_num_pairs(d); ++q) {
    JetPair e = jet_pair(d, q);
    auto [ai, bi] = shift(e.i, h2);
    auto [aj, bj] = shift(e.j, h2);
    out[jet_first(d, 2) + q] = (f(ai + aj, bi + bj) - f(ai - aj, bi - bj) - f(-ai + aj, -bi + bj) +
                                f(-ai - aj, -bi - bj)) / (4 * h2 * h2);
  }
  for (int t = 0; t < jet_num_triples(d); ++t) {
    JetTriple e = jet_triple(d, t);
    auto [ai, bi] = shift(e.i, h3);
    auto [aj, bj] = shift(e.j, h3);
    auto [ak, bk] = shift(e.k, h3);
    double s = 0;
    for (int si : {1, -1})
      for (int sj : {1, -1})
        for (int sk : {1, -1})
          s += si * sj * sk * f(si * ai + sj * aj + sk * ak, si * bi + sj * bj + sk * bk);
    out[jet_first(d, 3) + t] = s / (8 * h3 * h3 * h3);
  }
  return out;
}

}  // namespace

class JetForward : public ::testing::TestWithParam<int> {};

TEST_P(JetForward, DerivativesMatchFiniteDifferences) {
  const int d = GetParam();
  NetworkDesc desc;
  desc.input_dim = d;
  auto p = test::random_params(desc, 7 + d);
  const int B = 5;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.4, 1.4);
  std::vector<double> x(B * d);
  for (double& v : x) v = u(rng);
  const int C = jet_channels(d, 3);
  std::vector<double> jet(C * B);
  cpu::JetWorkspace<double> ws;
  cpu::mlp_jet_forward<double>(desc, p.data(), x.data(), B, 3, jet.data(), ws);
  for (int b = 0; b < B; ++b) {
    auto ref = fd_jet(desc, p, &x[b * d]);
    for (int c = 0; c < C; ++c) {
      const double got = jet[c * B + b];
      const double tol = c == 0 ? 1e-14 : c <= d ? 1e-8 : c < jet_first(d, 3) ? 1e-6 : 2e-5;
      EXPECT_NEAR(got, ref[c], tol * (1 + std::abs(ref[c]))) << "d=" << d << " point " << b << " channel " << c;
    }
  }
}

TEST_P(JetForward, LowerOrdersAreTruncationsOfTheFullJet) {
  const int d = GetParam();
  NetworkDesc desc;
  desc.input_dim = d;
  auto p = test::random_params(desc, 3);
  const int B = 7;
  std::vector<double> x(B * d);
  for (int i = 0; i < B * d; ++i) x[i] = -1.0 + 0.3 * i;
  cpu::JetWorkspace<double> ws;
  std::vector<double> full(jet_channels(d, 3) * B);
  cpu::mlp_jet_forward<double>(desc, p.data(), x.data(), B, 3, full.data(), ws);
  for (int order = 0; order < 3; ++order) {
    std::vector<double> part(jet_channels(d, order) * B);
    cpu::mlp_jet_forward<double>(desc, p.data(), x.data(), B, order, part.data(), ws);
    for (size_t i = 0; i < part.size(); ++i) EXPECT_NEAR(part[i], full[i], 1e-13 * (1 + std::abs(full[i])));
  }
}

INSTANTIATE_TEST_SUITE_P(Dims, JetForward, ::testing::Values(1, 2));
