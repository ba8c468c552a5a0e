// Where the continuum strip's middle leaves the material's data boxes (accuracy/box_reach.hpp).
#include <gtest/gtest.h>

#include "accuracy/box_reach.hpp"

using namespace yarnhom;

namespace {
BakedTable table1d(const std::string& name, double lo, double hi) {
  BakedTable t;
  t.term = term_by_name(name);
  t.lower = {lo};
  t.upper = {hi};
  return t;
}
}  // namespace

TEST(BoxReach, FindsTheFirstTestAtEachBoundAndNothingInside) {
  BakedModel m;
  m.tables = {table1d("0", -0.2, 1.0), table1d("1", -0.7, 0.7), table1d("2", -0.2, 1.0)};
  const std::vector<double> stretch = {1.0, 1.1, 1.2, 1.3, 1.4};
  // s_x well inside; s_a inside; s_y within 1 % of the box width (0.012) of -0.2 from test 3.
  std::vector<std::vector<double>> mid = {{0.0, 0.1, 0.2, 0.3, 0.4},
                                          {0.0, 0.01, 0.02, 0.01, 0.0},
                                          {0.0, -0.1, -0.18, -0.1895, -0.2049}};
  auto r = box_reach(m, mid);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].component, 2);
  EXPECT_FALSE(r[0].upper);
  EXPECT_EQ(r[0].first, 3u);
  EXPECT_DOUBLE_EQ(r[0].bound, -0.2);
  EXPECT_DOUBLE_EQ(r[0].extreme, -0.2049);
  const std::string text = box_reach_text(r, stretch);
  EXPECT_NE(text.find("lower bound s_y = -0.2 at 130 %"), std::string::npos) << text;
  // The upper bound of s_x, and a shear past its box, are found too; -0.18 is not within 1 %.
  mid[0] = {0.0, 0.5, 0.9, 0.995, 1.02};
  mid[1] = {0.0, 0.0, 0.0, 0.0, -0.75};
  r = box_reach(m, mid);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].component, 0);
  EXPECT_TRUE(r[0].upper);
  EXPECT_EQ(r[0].first, 3u);
  EXPECT_EQ(r[1].component, 1);
  EXPECT_EQ(r[1].first, 4u);
  // Nothing reached: no text; a material without the term, or an empty column, is skipped.
  mid = {{0.0, 0.1}, {0.0, 0.0}, {0.0, -0.05}};
  EXPECT_TRUE(box_reach(m, mid).empty());
  EXPECT_EQ(box_reach_text(box_reach(m, mid), stretch), "");
  BakedModel none;
  EXPECT_TRUE(box_reach(none, {{-5.0}, {5.0}, {-5.0}}).empty());
  EXPECT_TRUE(box_reach(m, {{}, {}, {}}).empty());
}
