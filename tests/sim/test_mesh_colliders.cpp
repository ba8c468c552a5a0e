// Mesh colliders from OBJ files (sim/obstacles.hpp) through scene files: a sheet falls onto a
// static triangle plate and rests on it, a plate moving up frame by frame lifts a sheet, each
// checked every frame with the exact intersection test; frames that do not match, and scene
// keys that do not exist, are refused naming the file and the key; seams from a scene file close
// a tube.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <cmath>
#include <fstream>
#include <sstream>

#include "sim/contact.hpp"
#include "sim/garment.hpp"
#include "sim/scene_json.hpp"
#include "sim/simulation.hpp"
#include "tests/common/poly_material.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;
namespace fs = std::filesystem;

namespace {

const MaterialFn& material() { return test::simple_cloth_material(); }

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("yarnhom_meshcol_" + std::to_string(::getpid()) + "_" + name);
  fs::create_directories(d);
  return d;
}

// A square plate of half-size s at height z, split in 4 triangles around its centre.
void write_plate(const fs::path& p, double s, double z) {
  std::ofstream f(p);
  f << "v " << -s << " " << -s << " " << z << "\nv " << s << " " << -s << " " << z << "\nv " << s << " " << s << " " << z
    << "\nv " << -s << " " << s << " " << z << "\nv 0 0 " << z << "\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
}

void write_text(const fs::path& p, const std::string& s) { std::ofstream(p) << s; }

// A 0.2 m sheet (8 x 8 quads) centred at the origin, 2 cm above z = 0, falling on `colliders`.
std::string sheet_scene(const std::string& colliders, int frames) {
  return R"({"mesh": {"rectangle": {"width": 0.2, "height": 0.2, "nx": 8, "ny": 8}},
             "position": {"translate": [-0.1, -0.1, 0.02]}, "areal_density": 0.2, "friction": 0.3,
             "frames": )" + std::to_string(frames) + R"(, "colliders": [)" + colliders + "]}";
}

Problem check_problem(const Scene& s) {
  Problem P = make_problem(s.mesh, material(), 0.2);
  P.obstacles = s.obstacles;
  finish_obstacles(P.obstacles);
  P.self_collision = true;
  P.edges = cloth_edges(P.mesh);
  return P;
}

}  // namespace

TEST(MeshColliders, SheetRestsOnAStaticPlateWithoutIntersecting) {
  const fs::path d = scratch("static");
  write_plate(d / "plate.obj", 0.06, 0.0);
  write_text(d / "scene.json", sheet_scene(R"({"mesh": {"obj": "plate.obj"}})", 20));
  const Scene s = read_scene_json((d / "scene.json").string());
  ASSERT_EQ(s.obstacles.meshes.size(), 1u);
  const Problem P = check_problem(s);
  const SimResult r = run_simulation(s, material(), 0.2, SimSettings{}, [&](int frame, const SimResult& R) {
    std::string what;
    EXPECT_FALSE(contact_intersections(P, R.x, R.obstacles, &what)) << "frame " << frame << ": " << what;
  });
  ASSERT_TRUE(r.finite);
  // The centre vertex lies on the plate, within the barrier's reach above it; the free corners
  // hang below it.
  const int centre = 4 * 9 + 4;
  EXPECT_GT(r.x[3 * centre + 2], 0.0);
  EXPECT_LT(r.x[3 * centre + 2], s.dhat);
  EXPECT_LT(r.x[2], -0.01);
  fs::remove_all(d);
}

TEST(MeshColliders, PlateMovingUpFrameByFrameLiftsTheSheet) {
  // Frames 1/30 s apart: the plate rises 3 cm per frame from 1 cm below the sheet.
  const fs::path d = scratch("moving");
  std::string frames;
  for (int k = 0; k < 8; ++k) {
    write_plate(d / ("p" + std::to_string(k) + ".obj"), 0.06, 0.01 + 0.03 * k);
    frames += std::string(k ? ", " : "") + "\"p" + std::to_string(k) + ".obj\"";
  }
  write_text(d / "scene.json", sheet_scene(R"({"mesh": {"frames": [)" + frames + "]}}", 10));
  Scene s = read_scene_json((d / "scene.json").string());
  s.gravity.setZero();  // the sheet floats until the plate takes it
  for (int v = 0; v < s.mesh.num_vertices(); ++v) s.mesh.x(v, 2) = 0.02;
  const Problem P = check_problem(s);
  const SimResult r = run_simulation(s, material(), 0.2, SimSettings{}, [&](int frame, const SimResult& R) {
    std::string what;
    EXPECT_FALSE(contact_intersections(P, R.x, R.obstacles, &what)) << "frame " << frame << ": " << what;
    // Over the plate's middle the sheet is never below it.
    EXPECT_GT(R.x[3 * (4 * 9 + 4) + 2], R.obstacles[3 * 4 + 2]) << "frame " << frame;
  });
  ASSERT_TRUE(r.finite);
  EXPECT_NEAR(r.obstacles[3 * 4 + 2], 0.01 + 0.03 * 7, 1e-9);  // the plate reached its last frame
  EXPECT_GT(r.x[3 * (4 * 9 + 4) + 2], 0.2);                  // and carried the sheet up
  fs::remove_all(d);
}

TEST(MeshColliders, HeldFramesAndPathSegmentsGiveTheirPositionsExactly) {
  // A body held still over its first two frames (the same OBJ twice: the moving-body tests'
  // sequences) and a capsule holding an offset between two path points: between them the
  // positions are the frame's and the offset's bit for bit (interpolated as (1 - u) a + u a they
  // were off by 2e-16 m at most steps, and the one-solve step took the body for moving there,
  // sim/integrators.hpp); the moving part is interpolated as before.
  ObstacleSet o;
  MeshObstacle m = capsules_mesh({CapsuleObstacle{{0.1, -0.2, 1.3}, {0.7, 0.3, 1.34}, 0.04}}, 8, 2);
  m.frames.push_back(m.frames[0]);
  m.frames.push_back(m.frames[0]);
  m.frames[2].col(0).array() += 0.2;
  m.frame_dt = 0.4;
  o.meshes.push_back(m);
  CapsuleObstacle c;
  c.a = Eigen::Vector3d(0.3, 0.7, 1.1);
  c.path = {{0.0, 0.0, 0.0, 0.0}, {0.1, 0.3, -0.7, 0.11}, {0.5, 0.3, -0.7, 0.11}, {0.9, 0.6, -0.7, 0.11}};
  o.capsules.push_back(c);
  finish_obstacles(o);
  const int nm = int(m.frames[0].rows());
  for (int s = 1; s <= 30; ++s) {
    const double t = s / 30.0;
    const Eigen::VectorXd y = obstacle_positions(o, t);
    const Eigen::Vector3d d = y.segment<3>(0) - c.a;
    if (t >= 0.1 && t <= 0.5) {
      EXPECT_EQ(y.segment<3>(0), c.a + Eigen::Vector3d(0.3, -0.7, 0.11)) << "t " << t;
    }
    if (t > 0.5) EXPECT_GT(d[0], 0.3) << "t " << t;
    for (int v = 0; v < nm; ++v) {
      const Eigen::Vector3d p = y.segment<3>(3 * (2 + v));
      if (t <= 0.4) ASSERT_EQ(p, m.frames[0].row(v).transpose()) << "t " << t << ", vertex " << v;
      else ASSERT_NEAR(p[0], m.frames[0](v, 0) + 0.2 * std::min(1.0, t / 0.4 - 1), 1e-12) << "t " << t;
    }
  }
}

TEST(MeshColliders, MismatchedFramesAndUnknownKeysAreRefusedByName) {
  const fs::path d = scratch("bad");
  write_plate(d / "a.obj", 0.06, 0.0);
  write_text(d / "b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write_text(d / "s1.json", sheet_scene(R"({"mesh": {"frames": ["a.obj", "b.obj"]}})", 1));
  try {
    read_scene_json((d / "s1.json").string());
    FAIL() << "accepted frames with different vertex counts";
  } catch (const std::exception& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("b.obj"), std::string::npos) << m;
    EXPECT_NE(m.find("colliders[0].mesh"), std::string::npos) << m;
  }
  write_text(d / "s2.json", sheet_scene(R"({"capsule": {"a": [0, 0, 0], "b": [1, 0, 0], "radiu": 0.01}})", 1));
  try {
    read_scene_json((d / "s2.json").string());
    FAIL() << "accepted an unknown key";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("radiu"), std::string::npos) << e.what();
  }
  write_text(d / "s3.json", sheet_scene(R"({"mesh": {"obj": "missing.obj"}})", 1));
  EXPECT_THROW(read_scene_json((d / "s3.json").string()), std::exception);
  fs::remove_all(d);
}

TEST(MeshColliders, SeamsFromASceneFileCloseATube) {
  // An OBJ sheet bent 300 degrees around z (rest: vt in metres), its two free edges stitched
  // by the scene file's "seams": they close within the sewing time without intersecting.
  const fs::path d = scratch("seams");
  const int N = 12, M = 3;
  const double W = 0.24, dz = 0.03, span = 300.0 * M_PI / 180, R = W / span;
  std::ostringstream obj;
  for (int j = 0; j <= M; ++j)
    for (int i = 0; i <= N; ++i) {
      const double th = span * i / N;
      obj << "v " << R * std::cos(th) << " " << R * std::sin(th) << " " << dz * j << "\n";
      obj << "vt " << W * i / N << " " << dz * j << "\n";
    }
  auto id = [&](int i, int j) { return j * (N + 1) + i + 1; };
  for (int j = 0; j < M; ++j)
    for (int i = 0; i < N; ++i)
      obj << "f " << id(i, j) << "/" << id(i, j) << " " << id(i + 1, j) << "/" << id(i + 1, j) << " " << id(i + 1, j + 1)
          << "/" << id(i + 1, j + 1) << "\nf " << id(i, j) << "/" << id(i, j) << " " << id(i + 1, j + 1) << "/"
          << id(i + 1, j + 1) << " " << id(i, j + 1) << "/" << id(i, j + 1) << "\n";
  write_text(d / "sheet.obj", obj.str());
  std::string stitches;
  for (int j = 0; j <= M; ++j)
    stitches += std::string(j ? ", " : "") + "[" + std::to_string(id(0, j) - 1) + ", " + std::to_string(id(N, j) - 1) + "]";
  write_text(d / "scene.json", R"({"mesh": {"obj": "sheet.obj"}, "areal_density": 0.2, "gravity": [0, 0, 0],
    "frames": 10, "seams": {"stitches": [)" + stitches + R"(], "stiffness": 20, "sew_time": 0.2}})");
  const Scene s = read_scene_json((d / "scene.json").string());
  ASSERT_EQ(s.stitches.size(), size_t(M + 1));
  Problem P = check_problem(s);
  P.vertex_rep = stitch_representatives(P.mesh.num_vertices(), s.stitches);
  const SimResult r = run_simulation(s, material(), 0.2, SimSettings{}, [&](int frame, const SimResult& Rs) {
    std::string what;
    EXPECT_FALSE(contact_intersections(P, Rs.x, Rs.obstacles, &what)) << "frame " << frame << ": " << what;
  });
  ASSERT_TRUE(r.finite);
  for (const Stitch& st : s.stitches) EXPECT_LT((r.x.segment<3>(3 * st.a) - r.x.segment<3>(3 * st.b)).norm(), 2e-3);
  // A vertex out of range is refused, naming the key.
  write_text(d / "bad.json", R"({"mesh": {"obj": "sheet.obj"}, "seams": {"stitches": [[0, 999]]}})");
  try {
    read_scene_json((d / "bad.json").string());
    FAIL() << "accepted a stitch to a missing vertex";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("seams.stitches"), std::string::npos) << e.what();
  }
  fs::remove_all(d);
}
