// OBJ texture coordinates that other tools open: yarnhom writes them in [0, 1] with the
// "# yarnhom uv:" line that maps them back to rest positions in metres, writes the rest shape as
// rest.obj, and still reads files whose texture coordinates are metres (ARCSim-HYLC's convention).
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/obj_io.hpp"
#include "sim/rectangle.hpp"

using namespace yarnhom::sim;
namespace fs = std::filesystem;

namespace {

fs::path temp_path(const std::string& name) {
  return fs::temp_directory_path() / ("yarnhom_uv_" + std::to_string(::getpid()) + "_" + name);
}

// Every "vt u v" of a file.
std::vector<std::array<double, 2>> texcoords(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::array<double, 2>> out;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("vt ", 0) == 0) {
      std::istringstream ss(line.substr(3));
      std::array<double, 2> uv{};
      ss >> uv[0] >> uv[1];
      out.push_back(uv);
    }
  return out;
}

}  // namespace

TEST(ObjUv, WrittenTextureCoordinatesAreInTheUnitSquareAndReadBackAsRestPositions) {
  Mesh m = make_rectangle(0.3, 0.1, 6, 2);  // centred on the origin: negative rest positions
  m.rest.col(0).array() -= 0.2;
  ASSERT_LT(m.rest.minCoeff(), 0);
  const fs::path p = temp_path("frame.obj"), r = temp_path("rest.obj");
  write_obj(p.string(), m, m.x);
  double lo = 1, hi = 0;
  for (const auto& uv : texcoords(p))
    for (double c : uv) lo = std::min(lo, c), hi = std::max(hi, c);
  EXPECT_GE(lo, 0.0);
  EXPECT_LE(hi, 1.0);
  EXPECT_NEAR(hi, 1.0, 1e-12);  // the larger extent spans [0, 1]: the aspect is kept
  const Mesh back = read_obj(p.string());
  EXPECT_LT((back.rest - m.rest).cwiseAbs().maxCoeff(), 1e-9);

  write_rest_obj(r.string(), m);  // the rest shape in metres, z = 0
  const Mesh rest = read_obj(r.string());
  EXPECT_LT((rest.rest - m.rest).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((rest.x.leftCols(2) - m.rest).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(rest.x.col(2).cwiseAbs().maxCoeff(), 0.0);
  fs::remove(p);
  fs::remove(r);
}

TEST(ObjUv, FilesWithoutTheUvLineAreReadInMetresAndABadLineIsRefused) {
  const fs::path p = temp_path("old.obj");
  std::ofstream(p) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt -0.5 -0.25\nvt 0.5 -0.25\nvt -0.5 0.75\nf 1/1 2/2 3/3\n";
  const Mesh m = read_obj(p.string());
  EXPECT_DOUBLE_EQ(m.rest.col(0).minCoeff(), -0.5);
  EXPECT_DOUBLE_EQ(m.rest.col(1).minCoeff(), -0.25);
  std::ofstream(p) << "# yarnhom uv: rest_m = origin + scale * vt; origin 0 0 scale -1\n"
                      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
  EXPECT_THROW(read_obj(p.string()), std::invalid_argument);
  fs::remove(p);
}
