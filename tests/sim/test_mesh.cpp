// The mesh: flaps across edges (boundary -1, interior the opposite vertex of the neighbour),
// OBJ round trip with texture coordinates as rest positions, orientation handling, and bad
// files refused with the file and line named.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "sim/obj_io.hpp"
#include "sim/rectangle.hpp"

using namespace yarnhom::sim;
namespace fs = std::filesystem;

namespace {

std::string temp_file(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("yarnhom_sim_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p.string();
}

std::string error_of(const std::string& path) {
  try {
    read_obj(path);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Mesh, FlapsAreTheOppositeVerticesOfNeighbours) {
  const Mesh m = make_rectangle(1, 1, 3, 2);
  int boundary = 0;
  for (int t = 0; t < m.num_triangles(); ++t)
    for (int i = 0; i < 3; ++i) {
      const int a = m.tris(t, i), b = m.tris(t, (i + 1) % 3), f = m.flaps(t, i);
      if (f < 0) {
        ++boundary;
        continue;
      }
      // Some triangle holds (b, a, f) in this cyclic order.
      bool found = false;
      for (int u = 0; u < m.num_triangles() && !found; ++u)
        for (int j = 0; j < 3; ++j)
          found |= m.tris(u, j) == b && m.tris(u, (j + 1) % 3) == a && m.tris(u, (j + 2) % 3) == f;
      EXPECT_TRUE(found) << t << " " << i;
    }
  EXPECT_EQ(boundary, 2 * (3 + 2));  // the perimeter's edges
  EXPECT_NEAR(vertex_areas(m).sum(), 1.0, 1e-14);
}

TEST(Mesh, ObjRoundTripKeepsRestPositionsAndTriangles) {
  Mesh m = make_rectangle(0.05, 0.1, 2, 4);
  Eigen::MatrixX3d x = m.x;
  x.col(2).array() += 0.3;
  const std::string p = temp_file("rt.obj", "");
  write_obj(p, m, x);
  const Mesh r = read_obj(p);
  EXPECT_EQ(r.tris, m.tris);
  EXPECT_EQ(r.flaps, m.flaps);
  EXPECT_LT((r.rest - m.rest).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((r.x - x).cwiseAbs().maxCoeff(), 1e-9);
  fs::remove(p);
}

TEST(Mesh, ClockwiseTextureCoordinatesAreFlippedAndFoldsRefused) {
  // One quad, both triangles clockwise in (u, v): flipped to counterclockwise.
  const std::string cw = temp_file("cw.obj",
                                   "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                   "f 1/1 3/3 2/2\nf 1/1 4/4 3/3\n");
  const Mesh m = read_obj(cw);
  for (int t = 0; t < 2; ++t) {
    const Eigen::Vector2d u0 = m.rest.row(m.tris(t, 0)), u1 = m.rest.row(m.tris(t, 1)), u2 = m.rest.row(m.tris(t, 2));
    EXPECT_GT((u1 - u0).x() * (u2 - u0).y() - (u1 - u0).y() * (u2 - u0).x(), 0);
  }
  const std::string fold = temp_file("fold.obj",
                                     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                     "f 1/1 2/2 3/3\nf 1/1 4/4 3/3\n");
  EXPECT_NE(error_of(fold).find("fold over"), std::string::npos) << error_of(fold);
  fs::remove(cw);
  fs::remove(fold);
}

TEST(Mesh, BadObjFilesAreRefusedNamingFileAndLine) {
  const std::string novt = temp_file("novt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  std::string e = error_of(novt);
  EXPECT_NE(e.find(novt + ":4"), std::string::npos) << e;
  EXPECT_NE(e.find("texture"), std::string::npos) << e;
  const std::string range = temp_file("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 7/1\n");
  e = error_of(range);
  EXPECT_NE(e.find(range + ":5"), std::string::npos) << e;
  EXPECT_NE(e.find("out of range"), std::string::npos) << e;
  const std::string seam = temp_file("seam.obj",
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\nvt 5 5\n"
                                     "f 1/1 2/2 3/3\nf 2/9 4/4 3/3\n");
  e = error_of(seam);
  EXPECT_NE(e.find("seam"), std::string::npos) << e;
  const std::string nonmanifold = temp_file("nm.obj",
                                            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 0 -1\n"
                                            "f 1/1 2/2 3/3\nf 1/1 2/2 4/4\n");
  e = error_of(nonmanifold);
  EXPECT_FALSE(e.empty());
  EXPECT_NE(error_of("/nonexistent/x.obj").find("no such file"), std::string::npos);
  for (const auto& p : {novt, range, seam, nonmanifold}) fs::remove(p);
}
