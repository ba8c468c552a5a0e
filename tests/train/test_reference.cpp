// The C++ losses and parameter gradients against the PyTorch reference
// (scripts/reference/yarnhom_ref.py, autograd to third order) on identical weights and batches,
// in double: relative error under 1e-5. Skipped, with a message, when PyTorch is absent.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "core/h5.hpp"
#include "core/offdomain.hpp"
#include "cpu/loss_step.hpp"
#include "tests/common/random_net.hpp"

using namespace yarnhom;
namespace fs = std::filesystem;

namespace {

// A python3 that imports torch and h5py, or "" (YARNHOM_PYTHON overrides the search).
std::string find_python() {
  std::vector<std::string> cands;
  if (const char* p = std::getenv("YARNHOM_PYTHON")) cands.push_back(p);
  cands.push_back("/usr/bin/python3");
  cands.push_back("python3");
  for (const auto& c : cands)
    if (std::system((c + " -c 'import torch, h5py' >/dev/null 2>&1").c_str()) == 0) return c;
  return "";
}

double rel(const std::vector<double>& a, const std::vector<double>& b) {
  double n = 0, d = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    n += (a[i] - b[i]) * (a[i] - b[i]);
    d += b[i] * b[i];
  }
  return std::sqrt(n / d);
}

}  // namespace

class Reference : public ::testing::TestWithParam<int> {};

TEST_P(Reference, LossesAndGradientsMatchPyTorch) {
  static const std::string py = find_python();
  if (py.empty()) GTEST_SKIP() << "no python3 with torch and h5py: PyTorch comparison skipped";
  const int d = GetParam();
  NetworkDesc desc;
  desc.input_dim = d;
  auto params = test::random_params(desc, 77 + d);
  const int m = 37, k = 50;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> x(m * d), y(m), g(m * d), xo(k * d), no(k * d);
  for (auto& v : x) v = u(rng);
  for (auto& v : y) v = u(rng);
  for (auto& v : g) v = u(rng);
  for (int j = 0; j < k; ++j) offdomain_point<double>(d, rng_key(1, 2), j, &xo[j * d], &no[j * d]);
  cpu::LossOptions opt;
  opt.w.x = 0.5;  // every term active

  const fs::path dir = fs::temp_directory_path() / ("yarnhom_ref_" + std::to_string(::getpid()) + "_" + std::to_string(d));
  fs::create_directories(dir);
  const std::string in = (dir / "in.h5").string(), out = (dir / "out.h5").string();
  {
    auto f = h5::create_file(in);
    f.set_attr("d", d);
    f.set_attr("hidden", desc.hidden);
    f.set_attr("weights", std::vector<double>{opt.w.z, opt.w.f, opt.w.c, opt.w.s, opt.w.x});
    f.write("params", params, {params.size()});
    f.write("x", x, {x.size()});
    f.write("y", y, {y.size()});
    f.write("g", g, {g.size()});
    f.write("xo", xo, {xo.size()});
    f.write("no", no, {no.size()});
  }
  const std::string script = std::string(YARNHOM_SOURCE_DIR) + "/scripts/reference/yarnhom_ref.py";
  ASSERT_EQ(std::system((py + " " + script + " check " + in + " " + out).c_str()), 0);

  cpu::LossWorkspace<double> ws;
  std::vector<double> grad(params.size());
  cpu::LossBatch<double> b{m, x.data(), y.data(), g.data(), k, xo.data(), no.data()};
  cpu::LossValues v = cpu::mlp_loss_grad<double>(desc, params.data(), b, opt, grad.data(), ws);

  auto f = h5::open_file(out);
  const std::pair<const char*, double> terms[] = {{"total", v.total}, {"z", v.z}, {"f", v.f},
                                                  {"c", v.c},         {"s", v.s}, {"x", v.x}};
  for (auto [name, mine] : terms) {
    const double ref = f.attr_double(name);
    EXPECT_NEAR(mine, ref, 1e-5 * std::abs(ref) + 1e-300) << name;
    if (std::string(name) != "x" && std::string(name) != "s") {
      EXPECT_GT(ref, 0) << name << " must be active";
    }
  }
  EXPECT_LT(rel(grad, f.read_double("grad").data), 1e-5);
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Dims, Reference, ::testing::Values(1, 2));
