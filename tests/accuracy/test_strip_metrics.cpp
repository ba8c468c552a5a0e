// The accuracy study's means (accuracy/strip_metrics.hpp) and the readers of what strip and
// sim write (OBJ geometry, CSV columns).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "io/csv_columns.hpp"
#include "io/obj_read.hpp"
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

// The fabric's distance leaves the boundary yarn out: a yarn strip whose own yarn covers the
// continuum's rectangle exactly (rows of points 1 mm apart) and whose boundary yarn runs 1 cm
// beside it. The full distance sees the boundary lane (the alignment centres the bounding boxes,
// so the lane ends 5 mm outside the shifted surface); the fabric's is the grid's own spacing.
TEST(StripMetrics, BoundaryYarnIsLeftOutOfTheFabricDistance) {
  std::string yarn = "# a strip\n";
  const int nx = 51, ny = 101;  // 0..50 mm x 0..100 mm, 1 mm apart
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) yarn += "v " + std::to_string(1e-3 * i) + " " + std::to_string(1e-3 * j) + " 0\n";
  for (int j = 0; j < ny; ++j) yarn += "v 0.06 " + std::to_string(1e-3 * j) + " 0\n";  // the lane
  for (int j = 0; j < ny; ++j) {
    yarn += "g yarn\nl";
    for (int i = 0; i < nx; ++i) yarn += " " + std::to_string(j * nx + i + 1);
    yarn += "\n";
  }
  yarn += "g boundary\nl";
  for (int j = 0; j < ny; ++j) yarn += " " + std::to_string(nx * ny + j + 1);
  yarn += "\n";
  const std::string yobj = write_tmp("yarn.obj", yarn);
  const std::string sobj = write_tmp("surf.obj", "v 0 0 0\nv 0.05 0 0\nv 0.05 0.1 0\nv 0 0.1 0\nf 1 2 3 4\n");

  const ObjGeometry g = read_obj_geometry(yobj);
  ASSERT_EQ(g.line_groups.size(), size_t(ny + 1));
  EXPECT_EQ(g.line_groups.front(), "yarn");
  EXPECT_EQ(g.line_groups.back(), "boundary");
  EXPECT_EQ(points_outside_group(g, "boundary").cols(), nx * ny);
  EXPECT_EQ(points_outside_group(g, "nothing of that name").cols(), g.V.cols()) << "no such group: every point";

  const StepMetrics m = compare_step(yobj, sobj, 1.0, 1.0, 1.0, 5e-4);
  EXPECT_NEAR(m.hausdorff.points_to_surface, 0.005, 1e-9) << "the lane, 5 mm outside the centred surface";
  EXPECT_GT(m.hausdorff.symmetric, 0.005 - 1e-9);
  // The fabric's points lie on the surface (0 one way); the surface's samples are within half a
  // grid diagonal (0.71 mm) of a point the other way.
  EXPECT_NEAR(m.hausdorff_fabric.points_to_surface, 0.0, 1e-12);
  EXPECT_LE(m.hausdorff_fabric.symmetric, 0.5e-3 * std::sqrt(2.0) + 1e-9);
  EXPECT_NEAR(m.width_yarn, 0.06, 1e-9);
  EXPECT_NEAR(m.width_yarn_fabric, 0.05, 1e-9);

  std::vector<StepMetrics> s(2, m);
  s[1].hausdorff_fabric.symmetric = 0;
  EXPECT_NEAR(summarize(s).mean_hausdorff_fabric, 0.5 * m.hausdorff_fabric.symmetric, 1e-15);
  for (const auto& p : {yobj, sobj}) fs::remove(p);
}
