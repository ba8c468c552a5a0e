// The accuracy study's means (accuracy/strip_metrics.hpp) and the readers of what strip and
// sim write (OBJ geometry, CSV columns).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "accuracy/csv_columns.hpp"
#include "accuracy/obj_read.hpp"
#include "accuracy/strip_metrics.hpp"
#include "core/error.hpp"

using namespace yarnhom;
namespace fs = std::filesystem;

namespace {
std::string write_tmp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("yarnhom_acc_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p.string();
}
}  // namespace

TEST(StripMetrics, MeansAndRelativeErrorByHand) {
  std::vector<StepMetrics> s(3);
  s[0].n_yarn = 0.0;  s[0].n_cont = 0.5;   // 100 %: no load, excluded from the relative mean
  s[1].n_yarn = 10.0; s[1].n_cont = 9.0;
  s[2].n_yarn = 20.0; s[2].n_cont = 23.0;
  for (auto& m : s) {
    m.stress_diff = std::abs(m.n_yarn - m.n_cont);
    m.hausdorff.symmetric = 0.01;
  }
  s[2].hausdorff.symmetric = 0.04;
  const AccuracySummary a = summarize(s);
  EXPECT_EQ(a.tests, 3);
  EXPECT_NEAR(a.mean_stress_diff, (0.5 + 1 + 3) / 3.0, 1e-15);
  EXPECT_NEAR(a.mean_hausdorff, 0.02, 1e-15);
  EXPECT_EQ(a.rel_tests, 2);
  EXPECT_NEAR(a.mean_rel_error, (0.1 + 0.15) / 2, 1e-15);
  EXPECT_NEAR(a.ratio_of_means, 4.5 / 30.0, 1e-15);
}

TEST(StripMetrics, AlignmentMatchesPlacementNotShape) {
  Eigen::Matrix3Xd P(3, 4), V(3, 3);
  P << 0, 1, 0, 1, 0, 0, 2, 2, 0.1, 0.1, 0.1, 0.1;
  V << 5, 6, 5, 3, 3, 5, 1, 1, 1;
  const Eigen::Matrix3Xd A = align_surface_to_points(V, P);
  EXPECT_NEAR(0.5 * (A.row(0).minCoeff() + A.row(0).maxCoeff()), 0.5, 1e-15);
  EXPECT_NEAR(0.5 * (A.row(1).minCoeff() + A.row(1).maxCoeff()), 1.0, 1e-15);
  EXPECT_NEAR(A.row(2).mean(), 0.1, 1e-15);
  EXPECT_NEAR((A.col(1) - A.col(0)).norm(), (V.col(1) - V.col(0)).norm(), 1e-15);
}

TEST(StripMetrics, ReadersOfObjAndCsv) {
  const std::string obj = write_tmp("g.obj",
                                    "# test\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1 4/1\nl 1 2 3\n");
  ObjGeometry g = read_obj_geometry(obj);
  EXPECT_EQ(g.V.cols(), 4);
  EXPECT_EQ(g.F.cols(), 2);  // the quad fanned into two triangles
  ASSERT_EQ(g.lines.size(), 1u);
  EXPECT_EQ(g.lines[0].size(), 3u);
  const std::string bad = write_tmp("b.obj", "v 0 0 0\nf 1 2 3\n");
  EXPECT_THROW(read_obj_geometry(bad), FileError);
  const std::string csv = write_tmp("f.csv", "# force\nstretch,force_N_per_m\n1.0,0\n1.05,2.5\n");
  CsvColumns t = read_csv_columns(csv);
  EXPECT_EQ(csv_column(t, {"ratio", "stretch"}, csv).size(), 2u);
  EXPECT_DOUBLE_EQ(csv_column(t, {"force_N_per_m"}, csv)[1], 2.5);
  EXPECT_THROW(csv_column(t, {"nope"}, csv), FileError);
  const std::string badcsv = write_tmp("c.csv", "a,b\n1,x\n");
  EXPECT_THROW(read_csv_columns(badcsv), FileError);
  // Only the columns asked for must be numbers (strip's force.csv ends with a status column).
  const CsvColumns a = read_csv_columns(badcsv, {"a"});
  EXPECT_EQ(a.count("b"), 0u);
  EXPECT_DOUBLE_EQ(csv_column(a, {"a"}, badcsv)[0], 1.0);
  EXPECT_THROW(read_csv_columns(badcsv, {"b"}), FileError);
  for (const auto& p : {obj, bad, csv, badcsv}) fs::remove(p);
}
