// The .pyp reader refuses each kind of malformed file with the line and the problem; writing
// and reading back is exact; the paper's patterns load.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "core/error.hpp"
#include "tests/common/yarn_support.hpp"
#include "yarn/rod/pattern.hpp"

using namespace yarnhom;
using namespace yarnhom::yarn;

namespace {

// A valid 3-vertex closed yarn crossing the tile along x (lines numbered in comments).
std::string good() {
  return "*pattern # px py radius n\n"  // 1
         "0.003 0.002 0.0001 3\n"       // 2
         "\n"                           // 3
         "*Q\n"                         // 4
         "-0.001 0 0 0\n"               // 5
         "0 0.0001 0 0\n"               // 6
         "0.001 0 0 0\n"                // 7
         "\n"                           // 8
         "*E\n"                         // 9
         "0 1 0 0\n"                    // 10
         "1 2 0 0\n"                    // 11
         "2 0 1 0\n";                   // 12
}

std::string error_of(const std::string& text) {
  try {
    parse_pyp(text, "t.pyp");
  } catch (const FileError& e) {
    return e.what();
  }
  return "";
}

std::string replace(std::string s, const std::string& a, const std::string& b) {
  const auto i = s.find(a);
  EXPECT_NE(i, std::string::npos) << a;
  return s.replace(i, a.size(), b);
}

}  // namespace

TEST(Pyp, ValidFileParsesAndFillsRestState) {
  const Pattern p = parse_pyp(good(), "t.pyp");
  ASSERT_EQ(p.size(), 3);
  EXPECT_DOUBLE_EQ(p.px, 0.003);
  EXPECT_EQ(p.edges[2].dx, 1);
  const Topology t = topology(p);
  EXPECT_EQ(t.yarns.size(), 1u);
  EXPECT_NEAR(p.rest_length[0], std::hypot(0.001, 0.0001), 1e-15);
  for (int v = 0; v < 3; ++v) EXPECT_NEAR(p.ref_d1[v].dot(stored_edge(p, t, v).normalized()), 0, 1e-12);
}

TEST(Pyp, MalformedFilesNameLineAndProblem) {
  struct Case {
    std::string text, expect;
  };
  const std::vector<Case> cases = {
      {replace(good(), "0.003 0.002 0.0001 3", "0.003 0.002 0.0001 4"), "t.pyp: line 4: *Q has 3 entries, *pattern (line 2) says 4"},
      {replace(good(), "*E\n", "*Edges\n"), "t.pyp: line 9: unknown block '*Edges'"},
      {replace(good(), "0 0.0001 0 0", "0 0.0001 zero 0"), "t.pyp: line 6: field 3 'zero' of *Q is not a finite number"},
      {replace(good(), "1 2 0 0", "1 7 0 0"), "t.pyp: line 11: edge to missing vertex 7"},
      {replace(good(), "2 0 1 0", "2 0 2 0"), "t.pyp: line 12: offsets dx=2 dy=0 outside -1..1"},
      {replace(good(), "0 0.0001 0 0", "-0.001 0 0 0"), "t.pyp: line 10: zero-length edge 0 -> 1"},
      {replace(good(), "0 1 0 0", "0 1 0"), "t.pyp: line 10: *E expects 4 fields"},
      {replace(good(), "1 2 0 0", "0 2 0 0"), "t.pyp: line 11: vertex 0 already has an outgoing edge (line 10)"},
      {"0 0 0 0\n" + good(), "t.pyp: line 1: data before any block header"},
      {replace(good(), "*E\n0 1 0 0\n1 2 0 0\n2 0 1 0\n", ""), "t.pyp: missing block *E"},
      {good() + "\n*RL\n1\n1\n1\n", "must be all present or all absent"},
  };
  for (const auto& c : cases) {
    const std::string msg = error_of(c.text);
    EXPECT_NE(msg.find(c.expect), std::string::npos) << "expected '" << c.expect << "', got '" << msg << "'";
  }
}

TEST(Pyp, WriteReadRoundTripIsExact) {
  Pattern p = parse_pyp(good(), "t.pyp");
  p.theta = {0.1, -0.2, 0.3};
  p.rest_kappa[1] = Eigen::Vector2d(0.25, -1.0 / 3.0);
  const Pattern q = parse_pyp(format_pyp(p), "again.pyp");
  ASSERT_EQ(q.size(), p.size());
  for (int v = 0; v < p.size(); ++v) {
    EXPECT_EQ(q.x[v], p.x[v]);
    EXPECT_EQ(q.theta[v], p.theta[v]);
    EXPECT_EQ(q.rest_length[v], p.rest_length[v]);
    EXPECT_EQ(q.rest_kappa[v], p.rest_kappa[v]);
    EXPECT_EQ(q.ref_d1[v], p.ref_d1[v]);
    EXPECT_EQ(q.ref_twist[v], p.ref_twist[v]);
  }
  const auto path = std::filesystem::temp_directory_path() / "yarnhom_test_roundtrip.pyp";
  write_pyp(path.string(), p);
  const Pattern r = read_pyp(path.string());
  EXPECT_EQ(r.name, "yarnhom_test_roundtrip");
  EXPECT_EQ(format_pyp(r), format_pyp(p));
  std::filesystem::remove(path);
}

TEST(Pyp, MissingFileIsNamed) {
  try {
    read_pyp("/nonexistent/dir/x.pyp");
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/x.pyp"), std::string::npos);
  }
}

TEST(Pyp, TilingKeepsClosedYarnsAndEdgeVectors) {
  const Pattern p = parse_pyp(good(), "t.pyp");
  const Pattern q = tile(p, 2, 3);
  EXPECT_EQ(q.size(), 6 * p.size());
  EXPECT_DOUBLE_EQ(q.px, 2 * p.px);
  const Topology tp = topology(p), tq = topology(q);
  for (int v = 0; v < q.size(); ++v)
    EXPECT_NEAR((stored_edge(q, tq, v) - stored_edge(p, tp, v % p.size())).norm(), 0, 1e-15);
  EXPECT_EQ(tq.yarns.size(), 3u);  // 3 rows; each yarn spans the 2 copies along x
}

TEST(Pyp, SharedPatternsLoadWithConsistentConventions) {
  YARN_REQUIRE_SHARED_PATTERNS();
  for (const char* name : {"stocktiny", "stocktiniest", "basket", "stockinette", "slip_stitch_honeycomb",
                           "cartridge_belt_rib", "satin"}) {
    const Pattern p = read_pyp(yarnhom::yarn::testing::shared_pattern(name));
    const Topology t = topology(p);
    // Reference directors are perpendicular to the vertex's outgoing edge (the convention
    // documented in pattern.hpp; the file's are rounded to about 6 digits).
    // (basket's coordinates have 6 significant digits: its worst edge is off by 0.1).
    double worst = 0, mean = 0;
    for (int v = 0; v < p.size(); ++v) {
      const double c = std::abs(p.ref_d1[v].normalized().dot(stored_edge(p, t, v).normalized()));
      worst = std::max(worst, c);
      mean += c / p.size();
    }
    EXPECT_LT(worst, 0.15) << name;
    EXPECT_LT(mean, 0.01) << name;
  }
}
