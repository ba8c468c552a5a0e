// HYLC's material format: a hand-made file whose splines encode known polynomials evaluates
// exactly (inside the knots, and HYLC's linear / tangent extrapolation outside), bending
// through the principal-curvature mixing ([g(K)]_00 = a (II_x^2 + II_a^2) for g = a l^2);
// malformed files are refused naming the file and the key; a baked file exported and read back
// evaluates like the baked file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "material/hylc_material.hpp"
#include "tests/common/fd_util.hpp"
#include "tests/common/poly_material.hpp"

using namespace yarnhom;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

std::string temp_path(const std::string& name) {
  return (fs::temp_directory_path() / ("yarnhom_hylc_" + std::to_string(::getpid()) + "_" + name)).string();
}

// Scales (HYLC's "strain scale") and the polynomials, in scaled strains S = s / c:
//   1D k=0: P0(S) = 2 S^2 + 0.5 S^3        1D k=1: P1(S) = 0.7 S^2
//   1D k=2: P2(S) = 1.5 S^2 - 0.2 S^3      1D k=3: 0.02 S^2 (bending x)   1D k=4: 0.03 S^2
//   2D (0,2): Q(u, v) = 0.3 u v + 0.1 u^2 v^3
//   2D (0,3): R(u, w) = 0.05 u w^2
const double kScale[5] = {0.8, 0.75, 0.9, 200, 150};
double P0(double S, int d) { return d == 0 ? 2 * S * S + 0.5 * S * S * S : d == 1 ? 4 * S + 1.5 * S * S : 4 + 3 * S; }
double P1(double S, int d) { return d == 0 ? 0.7 * S * S : d == 1 ? 1.4 * S : 1.4; }
double P2(double S, int d) { return d == 0 ? 1.5 * S * S - 0.2 * S * S * S : d == 1 ? 3 * S - 0.6 * S * S : 3 - 1.2 * S; }
double Q(double u, double v, int du, int dv) {
  // 0.3 u v + 0.1 u^2 v^3
  if (du == 0 && dv == 0) return 0.3 * u * v + 0.1 * u * u * v * v * v;
  if (du == 1 && dv == 0) return 0.3 * v + 0.2 * u * v * v * v;
  if (du == 0 && dv == 1) return 0.3 * u + 0.3 * u * u * v * v;
  if (du == 1 && dv == 1) return 0.3 + 0.6 * u * v * v;
  return 0;
}
double R(double u, double w, int du, int dw) {  // 0.05 u w^2
  if (du == 0 && dw == 0) return 0.05 * u * w * w;
  if (du == 1 && dw == 0) return 0.05 * w * w;
  if (du == 0 && dw == 1) return 0.1 * u * w;
  if (du == 1 && dw == 1) return 0.1 * w;
  return 0;
}

std::vector<double> knots(double lo, double hi, int n) {
  std::vector<double> t;
  // Deliberately non-uniform.
  for (int k = 0; k < n; ++k) {
    const double x = double(k) / (n - 1);
    t.push_back(lo + (hi - lo) * (x + 0.15 * std::sin(M_PI * x) * (1 - x)));
  }
  return t;
}

json spline1(int k, double (*P)(double, int), const std::vector<double>& t) {
  json s{{"k", k}, {"t", t}};
  std::vector<double> p, m;
  for (double x : t) {
    p.push_back(P(x, 0));
    m.push_back(P(x, 1));
  }
  s["p"] = p;
  s["m"] = m;
  return s;
}

json quad1(int k, double a, const std::vector<double>& t) {  // a S^2
  std::vector<double> p, m;
  for (double x : t) {
    p.push_back(a * x * x);
    m.push_back(2 * a * x);
  }
  return json{{"k", k}, {"t", t}, {"p", p}, {"m", m}};
}

json spline2(int k0, int k1, double (*F)(double, double, int, int), const std::vector<double>& tu, const std::vector<double>& tv) {
  std::vector<double> p, mu, mv, muv;
  for (double v : tv)
    for (double u : tu) {
      p.push_back(F(u, v, 0, 0));
      mu.push_back(F(u, v, 1, 0));
      mv.push_back(F(u, v, 0, 1));
      muv.push_back(F(u, v, 1, 1));
    }
  return json{{"k0", k0}, {"k1", k1}, {"tu", tu}, {"tv", tv}, {"p", p}, {"mu", mu}, {"mv", mv}, {"muv", muv}};
}

json handmade() {
  json j;
  j["density"] = 0.25;
  j["strain scale"] = std::vector<double>(kScale, kScale + 5);
  j["strain shift"] = {1, 0, 1, 0, 0};
  json co;
  co["const"] = 0.125;
  const auto t = knots(-1, 1.2, 9), tb = knots(-1.5, 1.5, 7);
  co["1D"] = {spline1(0, P0, t), spline1(1, P1, t), spline1(2, P2, t), quad1(3, 0.02, tb), quad1(4, 0.03, tb)};
  co["2D"] = {spline2(0, 2, Q, knots(-1, 1.2, 6), knots(-1, 1.1, 5)), spline2(0, 3, R, knots(-1, 1.2, 5), tb)};
  j["coeffs"] = co;
  return j;
}

// The closed form of the hand-made material, inside every knot range.
double expected_psi(const Strain6& s) {
  const double x = s[0] / kScale[0], a = s[1] / kScale[1], y = s[2] / kScale[2];
  const double c3 = kScale[3], c4 = kScale[4];
  const double K00 = s[3] * s[3] + s[4] * s[4], K11 = s[4] * s[4] + s[5] * s[5];  // [K^2]_00, [K^2]_11
  return 0.125 + P0(x, 0) + P1(a, 0) + P2(y, 0) + 0.02 * K00 / (c3 * c3) + 0.03 * K11 / (c4 * c4) + Q(x, y, 0, 0) +
         0.05 * x * K00 / (c3 * c3);
}

std::string write_json(const std::string& name, const json& j) {
  const std::string p = temp_path(name);
  std::ofstream(p) << j.dump();
  return p;
}

std::string error_of(const std::string& path) {
  try {
    read_hylc_material(path);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(HylcMaterial, HandMadePolynomialsEvaluateExactly) {
  const std::string path = write_json("poly.json", handmade());
  const HylcMaterial m = read_hylc_material(path);
  EXPECT_EQ(m.density, 0.25);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-0.6, 0.6);
  for (int n = 0; n < 50; ++n) {
    Strain6 s;
    s << U(rng), U(rng), U(rng), 200 * U(rng), 200 * U(rng), 150 * U(rng);
    if (n == 0) s << 0.1, 0.0, 0.2, 50, 0, 50;  // umbilic (II_x = II_y, II_a = 0)
    const MaterialEval e = eval_hylc_material(m, s);
    EXPECT_NEAR(e.psi, expected_psi(s), 1e-12) << s.transpose();
    auto f = [&](const Eigen::VectorXd& y) { return expected_psi(y); };
    const Eigen::VectorXd g = test::fd_gradient(f, s, 1e-6);
    Eigen::VectorXd gs = g, es = e.grad;
    for (int k = 3; k < 6; ++k) {  // compare on one scale
      gs[k] *= 200;
      es[k] *= 200;
    }
    EXPECT_LT((gs - es).cwiseAbs().maxCoeff(), 1e-7) << s.transpose();
    auto grad = [&](const Eigen::VectorXd& y) { return Eigen::VectorXd(eval_hylc_material(m, y).grad); };
    const Eigen::MatrixXd H = test::fd_jacobian(grad, s, 1e-6);
    Eigen::MatrixXd D = (H - e.hess).cwiseAbs();
    for (int i = 0; i < 6; ++i)
      for (int k = 0; k < 6; ++k) D(i, k) *= (i >= 3 ? 200 : 1) * (k >= 3 ? 200 : 1);
    EXPECT_LT(D.maxCoeff(), 1e-6) << s.transpose();
  }
  fs::remove(path);
}

TEST(HylcMaterial, ExtrapolatesLinearlyAsArcsimDoes) {
  const std::string path = write_json("extra.json", handmade());
  const HylcMaterial m = read_hylc_material(path);
  // 1D k=0 beyond its last knot T = 1.2 (scaled): P0(T) + P0'(T) (S - T), no other term moves
  // along s_x alone except Q and R, which vanish at y = 0, II = 0.
  const double T = 1.2, S = 1.7;
  Strain6 s = Strain6::Zero();
  s[0] = S * kScale[0];
  EXPECT_NEAR(eval_hylc_material(m, s).psi, 0.125 + P0(T, 0) + P0(T, 1) * (S - T), 1e-12);
  EXPECT_NEAR(eval_hylc_material(m, s).hess(0, 0), 0.0, 1e-12);
  // 2D corner beyond both upper knots (Q's tu ends at 1.2, tv at 1.1): bilinear tangent extension.
  const double u = 1.5, v = 1.4, U0 = 1.2, V0 = 1.1;
  s.setZero();
  s[0] = u * kScale[0];
  s[2] = v * kScale[2];
  const double corner = Q(U0, V0, 0, 0) + Q(U0, V0, 1, 0) * (u - U0) + Q(U0, V0, 0, 1) * (v - V0) + Q(U0, V0, 1, 1) * (u - U0) * (v - V0);
  const double ones = 0.125 + P0(T, 0) + P0(T, 1) * (u - T) + P2(T, 0) + P2(T, 1) * (v - T);  // both beyond 1.2
  EXPECT_NEAR(eval_hylc_material(m, s).psi, ones + corner, 1e-12);
  fs::remove(path);
}

TEST(HylcMaterial, MalformedFilesAreRefusedNamingFileAndKey) {
  struct Case {
    std::string name, expect;
    std::function<void(json&)> edit;
  };
  const std::vector<Case> cases = {
      {"nodensity", "'density'", [](json& j) { j.erase("density"); }},
      {"scale", "'strain scale'", [](json& j) { j["strain scale"] = {1, 2}; }},
      {"shift", "'strain shift'", [](json& j) { j["strain shift"] = {0, 0, 0, 0, 0}; }},
      {"m", "'coeffs.1D[2].m'", [](json& j) { j["coeffs"]["1D"][2].erase("m"); }},
      {"size", "'coeffs.1D[1].p'", [](json& j) { j["coeffs"]["1D"][1]["p"].erase(0); }},
      {"knots", "'coeffs.1D[0].t'", [](json& j) { j["coeffs"]["1D"][0]["t"][3] = -5; }},
      {"k", "'coeffs.1D[4].k'", [](json& j) { j["coeffs"]["1D"][4]["k"] = 7; }},
      {"k1", "'coeffs.2D[1].k1'", [](json& j) { j["coeffs"]["2D"][1]["k1"] = 0; }},
      {"mu", "'coeffs.2D[0].mu'", [](json& j) { j["coeffs"]["2D"][0]["mu"] = "x"; }},
      {"const", "'coeffs.const'", [](json& j) { j["coeffs"].erase("const"); }},
  };
  for (const Case& c : cases) {
    json j = handmade();
    c.edit(j);
    const std::string path = write_json(c.name + ".json", j);
    const std::string e = error_of(path);
    EXPECT_NE(e.find(path), std::string::npos) << c.name << ": " << e;
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.name << ": " << e;
    fs::remove(path);
  }
  const std::string bad = temp_path("bad.json");
  std::ofstream(bad) << "{\"density\": 0.3, ";
  EXPECT_NE(error_of(bad).find("not valid JSON"), std::string::npos) << error_of(bad);
  fs::remove(bad);
}

TEST(HylcMaterial, ExportedBakedFileEvaluatesLikeTheBakedFile) {
  // A baked material with every kind of term, bending included.
  auto terms = test::simple_cloth_terms();
  terms["12"].c[2][1] = 0.4;     // 0.4 sa^2 sy
  terms["03"].c[1][2] = 1e-6;    // sx II^2
  terms["25"].c[1][2] = -5e-7;   // sy II^2
  const BakedModel baked = test::poly_baked_model(terms, 0.05, 21, 11);
  const BakedMaterial bm = make_baked_material(baked);
  const std::string path = temp_path("export.json");
  write_hylc_material(path, hylc_from_baked(baked, 0.3, 0.5));
  const HylcMaterial hm = read_hylc_material(path);
  EXPECT_EQ(hm.density, 0.3);
  std::mt19937 rng(3);
  for (double reach : {0.95, 1.4}) {  // inside the boxes, then into the margin
    std::uniform_real_distribution<double> U(-reach, reach);
    for (int n = 0; n < 40; ++n) {
      // Box centres and half widths: s_x, s_y in [-0.2, 1], s_a in [-0.7, 0.7]; bending through
      // its principal curvatures, which the tables see, within +-200 reach (the margin reaches 400).
      const double l1 = 200 * U(rng), l2 = 200 * U(rng), phi = M_PI * U(rng), c = std::cos(phi), sn = std::sin(phi);
      Strain6 s;
      s << 0.4 + 0.6 * U(rng), 0.7 * U(rng), 0.4 + 0.6 * U(rng), c * c * l1 + sn * sn * l2, c * sn * (l1 - l2),
          sn * sn * l1 + c * c * l2;
      const MaterialEval a = eval_material(bm, s), b = eval_hylc_material(hm, s);
      EXPECT_NEAR(b.psi, a.psi, 1e-9 * (1 + std::abs(a.psi))) << reach << " " << s.transpose();
      for (int k = 0; k < 6; ++k) {
        const double w = k >= 3 ? 200 : 1;
        EXPECT_NEAR(b.grad[k] * w, a.grad[k] * w, 1e-8 * (1 + a.grad.cwiseAbs().maxCoeff() * 200)) << k;
      }
    }
  }
  fs::remove(path);
}
