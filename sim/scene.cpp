#include "sim/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sim/garment.hpp"
#include "sim/rectangle.hpp"

namespace yarnhom::sim {

Integrator parse_integrator(const std::string& name) {
  if (name == "newton") return Integrator::Newton;
  if (name == "linearized") return Integrator::Linearized;
  if (name == "baraff-witkin") return Integrator::BaraffWitkin;
  if (name == "static") return Integrator::Static;
  throw std::invalid_argument("integrator '" + name + "': expected newton, linearized, baraff-witkin or static");
}

const char* integrator_name(Integrator i) {
  switch (i) {
    case Integrator::Newton: return "newton";
    case Integrator::Linearized: return "linearized";
    case Integrator::BaraffWitkin: return "baraff-witkin";
    case Integrator::Static: return "static";
  }
  return "?";
}

bool is_builtin_scene(const std::string& name) {
  return name == "drape" || name == "hang" || name == "stretch" || name == "fold" || name == "tshirt";
}

int triangle_at(const Mesh& m, const Eigen::Vector2d& p) {
  int best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (int t = 0; t < m.num_triangles(); ++t) {
    const Eigen::Vector2d c = (m.rest.row(m.tris(t, 0)) + m.rest.row(m.tris(t, 1)) + m.rest.row(m.tris(t, 2))).transpose() / 3;
    const double d = (c - p).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = t;
    }
  }
  return best;
}

namespace {

Scene drape(int n) {
  const double L = 0.5, R = 0.15;
  Scene s;
  s.name = "drape";
  s.mesh = make_rectangle(L, L, n, n);
  // Sheet centred over the sphere's top, 5 cm above it.
  for (int v = 0; v < s.mesh.num_vertices(); ++v) s.mesh.x.row(v) << s.mesh.rest(v, 0) - L / 2, s.mesh.rest(v, 1) - L / 2, R + 0.05;
  Collider sphere;
  sphere.kind = Collider::Kind::Sphere;
  sphere.center = Eigen::Vector3d::Zero();
  sphere.radius = R;
  Collider floor;
  floor.kind = Collider::Kind::Plane;
  floor.center = Eigen::Vector3d(0, 0, -R);
  floor.normal = Eigen::Vector3d::UnitZ();
  // Woven and knitted cloth on smooth solids: kinetic friction coefficients of about 0.2-0.4.
  sphere.friction = floor.friction = 0.3;
  s.colliders = {sphere, floor};
  s.frames = 90;
  s.render_frames = {0, 15, 30, 90};
  return s;
}

Scene hang(int n) {
  const double L = 0.5;
  Scene s;
  s.name = "hang";
  s.mesh = make_rectangle(L, L, n, n);
  Handle pins;
  pins.vertices = {rectangle_vertex(n, 0, n), rectangle_vertex(n, n, n)};  // the two corners of the far (wale) edge
  s.handles = {pins};
  s.frames = 90;
  s.render_frames = {0, 10, 30, 90};
  return s;
}

Scene stretch(int n, char dir, const StretchSize& size) {
  const double L = size.length, W = size.width;
  if (!(W > 0 && L > 0 && std::isfinite(W) && std::isfinite(L)))
    throw std::invalid_argument("stretch: the strip's width and length must be positive");
  if (!(size.last >= 1.0 && size.last <= 10.0) || size.steps < 1)
    throw std::invalid_argument("stretch: the last stretch must lie in [1, 10] with at least one load step");
  const bool course = dir == 'x';
  // n quads across the width (default one per 5 mm: 10 on the paper's 5 cm), square along.
  if (n <= 0) n = std::max(2, int(std::lround(W / 0.005)));
  const int nl = std::max(1, int(std::lround(n * L / W))), nw = n;
  Scene s;
  s.name = course ? "stretch-course" : "stretch-wale";
  s.mesh = course ? make_rectangle(L, W, nl, nw) : make_rectangle(W, L, nw, nl);
  s.gravity.setZero();
  if (!(size.clamp >= 0 && size.clamp < L / 2))
    throw std::invalid_argument("stretch: the clamp band must lie in [0, length / 2)");
  // The clamps hold every vertex within the band of either end (the end rows at least), as the
  // yarn strip's do: with the end rows only, the continuum's free length would be L, the yarn's
  // L - 2 b, and the same clamp stretch would strain the yarn strip L / (L - 2 b) times more.
  Handle fixed, moving;
  const int along = course ? 0 : 1;
  const double band = size.clamp + 1e-9 * L;
  for (int v = 0; v < s.mesh.num_vertices(); ++v) {
    const double a = s.mesh.rest(v, along);
    if (a <= band) fixed.vertices.push_back(v);
    else if (a >= L - band) moving.vertices.push_back(v);
  }
  const Eigen::Vector3d axis = course ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d end = (size.last - 1.0) * L * axis;
  moving.path = {{0.0, 0, 0, 0}, {1.0, end.x(), end.y(), end.z()}};
  s.handles = {fixed, moving};
  s.integrator = Integrator::Static;
  s.frames = size.steps;  // load parameter k/steps: stretch 100 % + k (last - 1) / steps
  s.newton.tol_step = 1e-9;
  s.render_frames = {0, size.steps * 3 / 7, size.steps};
  s.stretch.enabled = true;
  s.stretch.moving_handle = 1;
  s.stretch.axis = axis;
  s.stretch.length = L;
  s.stretch.width = W;
  s.stretch.middle = course ? Eigen::Vector2d(L / 2, W / 2) : Eigen::Vector2d(W / 2, L / 2);
  return s;
}

// A 0.4 m square sheet 3 cm above a floor, over a thin rod (a capsule of radius 6 mm lying on
// the floor along the wale, under the sheet's middle). It falls onto rod and floor; from 0.3 s
// its left edge (a handle) is lifted over the rod and laid down above the right half (by
// 1.0 s), so that the left half folds over the rod onto the right one. Friction 0.3 with floor
// and rod, 0.2 between the layers.
Scene fold(int n) {
  const double L = 0.4, r = 0.006;
  Scene s;
  s.name = "fold";
  s.mesh = make_rectangle(L, L, n, n);
  for (int v = 0; v < s.mesh.num_vertices(); ++v) s.mesh.x.row(v) << s.mesh.rest(v, 0) - L / 2, s.mesh.rest(v, 1) - L / 2, 0.03;
  Collider floor;
  floor.kind = Collider::Kind::Plane;
  floor.center.setZero();
  floor.normal = Eigen::Vector3d::UnitZ();
  floor.friction = 0.3;
  s.colliders = {floor};
  CapsuleObstacle rod;
  rod.a = Eigen::Vector3d(0, -0.6 * L, r);
  rod.b = Eigen::Vector3d(0, 0.6 * L, r);
  rod.radius = r;
  rod.friction = 0.3;
  s.obstacles.capsules = {rod};
  s.self_friction = 0.2;
  Handle edge;
  for (int j = 0; j <= n; ++j) edge.vertices.push_back(rectangle_vertex(n, 0, j));
  // Up and over: (t, dx, dy, dz) from the edge's start at x = -L/2, z = 3 cm.
  edge.path = {{0.0, 0, 0, 0}, {0.3, 0, 0, 0}, {0.55, 0.12, 0, 0.14}, {0.8, 0.3, 0, 0.10}, {1.0, 0.37, 0, -0.003}};
  s.handles = {edge};
  s.frames = 45;
  s.render_frames = {0, 15, 25, 45};
  return s;
}

}  // namespace

Scene builtin_scene(const std::string& name, int resolution, char direction, const StretchSize& size) {
  if (resolution < 0 || resolution > 2000) throw std::invalid_argument("--resolution must be between 1 and 2000");
  if (name == "drape") return drape(resolution ? resolution : 40);
  if (name == "hang") return hang(resolution ? resolution : 30);
  if (name == "fold") return fold(resolution ? resolution : 24);
  if (name == "tshirt") return tshirt_scene(resolution ? resolution : 4);
  if (name == "stretch") {
    if (direction != 'x' && direction != 'y') throw std::invalid_argument("stretch direction must be course or wale");
    return stretch(resolution, direction, size);
  }
  throw std::invalid_argument("scene '" + name + "': not a built-in scene (drape, hang, stretch, fold, tshirt) nor a .json file");
}

}  // namespace yarnhom::sim
