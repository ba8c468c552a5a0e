// The rest check (bake/rest_check.hpp): at s = 0 the baked material's Hessian must be positive
// definite. A 1D term with negative curvature at 0 (basket's shear network) or a 2D coupling
// stronger than its two 1D stiffnesses (c^2 > K_I K_J) is reported unstable, naming the
// strains of the weakest direction; the in-plane stress at rest is reported as it is.
#include <gtest/gtest.h>

#include "bake/bake_table.hpp"
#include "material/material.hpp"
#include "bake/rest_check.hpp"
#include "tests/common/bake_test_util.hpp"

using namespace yarnhom;

namespace {

// Psi_0 = s_x^2 + 0.1 s_x, Psi_1 = k1 s_a^2 / 2, Psi_2 = s_y^2, Psi_02 = c s_x s_y (exact in
// the bicubic tables).
BakedMaterial material(double k1, double c) {
  test::Poly p0, p1, p2, p02;
  p0.c[2][0] = 1.0;
  p0.c[1][0] = 0.1;
  p1.c[2][0] = k1 / 2;
  p2.c[2][0] = 1.0;
  p02.c[1][1] = c;
  BakedModel m;
  m.tables = {bake_function(term_by_name("0"), {-0.5}, {1}, {61}, test::poly_function(p0, 1)),
              bake_function(term_by_name("1"), {-0.7}, {0.7}, {57}, test::poly_function(p1, 1)),
              bake_function(term_by_name("2"), {-0.5}, {1}, {61}, test::poly_function(p2, 1)),
              bake_function(term_by_name("02"), {-0.5, -0.5}, {1, 1}, {16, 16}, test::poly_function(p02, 2))};
  return make_baked_material(m);
}

}  // namespace

TEST(RestCheck, StableRestIsPositiveDefiniteAndItsStressIsReported) {
  const RestCheck r = check_rest(material(0.5, 1.0));
  EXPECT_TRUE(r.stable) << r.summary();
  EXPECT_NEAR(r.hess(0, 0), 2.0, 1e-9);
  EXPECT_NEAR(r.hess(1, 1), 0.5, 1e-9);
  EXPECT_NEAR(r.hess(0, 2), 1.0, 1e-9);
  EXPECT_NEAR(r.grad[0], 0.1, 1e-9);
  // Scaled: [[1, 0.5], [0.5, 1]] in (s_x, s_y) has eigenvalue 0.5; s_a alone 1; the absent
  // bending terms 0.
  EXPECT_NEAR(r.scaled_eigenvalues[0], 0.0, 1e-9);
  EXPECT_NEAR(r.scaled_eigenvalues[3], 0.5, 1e-9);
  EXPECT_NE(r.summary().find("rest: stable"), std::string::npos) << r.summary();
  EXPECT_NE(r.summary().find("in-plane stress at rest 0.1 "), std::string::npos) << r.summary();
}

TEST(RestCheck, NegativeShearCurvatureOrAStrongCouplingIsUnstable) {
  const RestCheck a = check_rest(material(-0.09, 1.0));  // basket's shear network at rest
  EXPECT_FALSE(a.stable);
  EXPECT_NEAR(a.scaled_eigenvalues[0], -1.0, 1e-9);
  EXPECT_NE(a.summary().find("UNSTABLE"), std::string::npos) << a.summary();
  EXPECT_NE(a.summary().find("mostly s_a)"), std::string::npos) << a.summary();
  // c = 3 > sqrt(2 x 2): the diagonal is positive, the pair (s_x, s_y) is not.
  const RestCheck b = check_rest(material(0.5, 3.0));
  EXPECT_FALSE(b.stable);
  EXPECT_NEAR(b.scaled_eigenvalues[0], 1.0 - 1.5, 1e-9);
  EXPECT_NE(b.summary().find("mostly s_x, s_y)"), std::string::npos) << b.summary();
}

// The RVE's own rest, from a dataset's measured rest Hessian, beside the material's.
TEST(RestCheck, RveRestNoteJudgesTheMeasuredHessianAlike) {
  EXPECT_EQ(rve_rest_note({}), "");
  std::vector<double> H(36, 0.0);
  for (int i = 0; i < 6; ++i) H[i * 7] = i < 3 ? 20.0 : 1e-7;  // strains and curvatures: other units
  H[0 * 6 + 3] = H[3 * 6 + 0] = -1e-3;                         // scaled coupling 1e-3 / sqrt(2e-6) = 0.71
  const std::string stable = rve_rest_note(H);
  EXPECT_NE(stable.find("stable, smallest scaled eigenvalue 0.293"), std::string::npos) << stable;
  H[0 * 6 + 3] = H[3 * 6 + 0] = -2e-3;  // 1.41: a negative direction
  EXPECT_NE(rve_rest_note(H).find("UNSTABLE"), std::string::npos) << rve_rest_note(H);
}
