// yarnhom rve --rest-hessian: the measured d2Psi/ds2 at rest (yarn/rve/rest_hessian.hpp) in the text
// and JSON outputs. The JSON matrix is symmetric and its diagonal equals produce's dataset
// attribute for the same pattern (one measurement, two commands); --start is refused with it.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "core/dataset.hpp"
#include "tests/common/run_cli.hpp"

namespace {

std::vector<double> json_array(const std::string& out, const std::string& key) {
  const size_t at = out.find("\"" + key + "\":[");
  if (at == std::string::npos) return {};
  std::string body = out.substr(at + key.size() + 4);
  body = body.substr(0, body.find(']'));
  std::vector<double> v;
  std::stringstream ss(body);
  std::string tok;
  while (std::getline(ss, tok, ',')) v.push_back(std::stod(tok));
  return v;
}

}  // namespace

TEST(CliRve, RestHessianInTextAndJsonMatchesProduce) {
  auto r = yarnhom::test::run_cli("rve stockinette --rest-hessian");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("rest Hessian d2Psi/ds2 at s = 0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("stable: smallest scaled eigenvalue"), std::string::npos) << r.out;
  r = yarnhom::test::run_cli("rve stockinette --rest-hessian --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::vector<double> H = json_array(r.out, "rest_hessian");
  ASSERT_EQ(H.size(), 36u) << r.out;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) EXPECT_EQ(H[i * 6 + j], H[j * 6 + i]);
  EXPECT_GT(H[0], 0.0);

  const std::string d = (std::filesystem::temp_directory_path() / ("yh_rve_" + std::to_string(getpid()))).string();
  std::filesystem::create_directories(d);
  r = yarnhom::test::run_cli("produce stockinette --preset tiny -o " + d + "/ds.h5 --threads 1");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("rest Hessian d2Psi/ds2 diagonal"), std::string::npos) << r.out;
  const yarnhom::Dataset ds = yarnhom::read_dataset(d + "/ds.h5");
  ASSERT_EQ(ds.rest_hessian.size(), 36u);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(ds.rest_hessian[i * 7], H[i * 7], 1e-6 * std::abs(H[i * 7])) << i;

  r = yarnhom::test::run_cli("rve stockinette --strain 0.01,0,0,0,0,0 --out " + d + "/st.h5");
  ASSERT_EQ(r.status, 0) << r.out;
  r = yarnhom::test::run_cli("rve stockinette --rest-hessian --start " + d + "/st.h5");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--rest-hessian needs the rest relaxation"), std::string::npos) << r.out;
  std::filesystem::remove_all(d);
}
