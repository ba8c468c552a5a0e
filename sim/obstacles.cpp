#include "sim/obstacles.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "io/obj_read.hpp"
#include "io/obj_write.hpp"

namespace yarnhom::sim {

bool ObstacleSet::moving() const {
  for (const CapsuleObstacle& c : capsules)
    if (!c.path.empty()) return true;
  for (const MeshObstacle& m : meshes)
    if (m.frames.size() > 1) return true;
  return false;
}

void finish_obstacles(ObstacleSet& o) {
  o.edges.clear(), o.tris.clear(), o.edge_radius.clear(), o.edge_friction.clear(), o.tri_friction.clear();
  o.point_friction.clear(), o.point_on_mesh.clear();
  int base = 0;
  for (const CapsuleObstacle& c : o.capsules) {
    if (!(c.radius > 0) || !std::isfinite(c.radius)) throw std::invalid_argument("a capsule's radius must be > 0");
    if (!(c.friction >= 0)) throw std::invalid_argument("a capsule's friction must be >= 0");
    o.edges.emplace_back(base, base + 1);
    o.edge_radius.push_back(c.radius);
    o.edge_friction.push_back(c.friction);
    for (int k = 0; k < 2; ++k) o.point_friction.push_back(c.friction), o.point_on_mesh.push_back(0);
    base += 2;
  }
  for (const MeshObstacle& m : o.meshes) {
    const int n = int(m.frames.at(0).rows());
    std::map<std::pair<int, int>, int> seen;
    for (int t = 0; t < m.tris.rows(); ++t) {
      o.tris.emplace_back(m.tris.row(t).transpose().array() + base);
      o.tri_friction.push_back(m.friction);
      for (int i = 0; i < 3; ++i) {
        int a = m.tris(t, i), b = m.tris(t, (i + 1) % 3);
        if (a > b) std::swap(a, b);
        if (seen.emplace(std::make_pair(a, b), 0).second) {
          o.edges.emplace_back(base + a, base + b);
          o.edge_radius.push_back(0.0);
          o.edge_friction.push_back(m.friction);
        }
      }
    }
    for (int k = 0; k < n; ++k) o.point_friction.push_back(m.friction), o.point_on_mesh.push_back(1);
    base += n;
  }
  o.num_points = base;
}

namespace {
Eigen::Vector3d path_offset(const std::vector<std::array<double, 4>>& path, double t) {
  if (path.empty()) return Eigen::Vector3d::Zero();
  auto at = [&](size_t k) { return Eigen::Vector3d(path[k][1], path[k][2], path[k][3]); };
  if (t <= path.front()[0]) return at(0);
  for (size_t k = 1; k < path.size(); ++k)
    if (t <= path[k][0]) {
      // A held segment gives its offset exactly: interpolating equal ends rounds (by 2e-16 m),
      // and a capsule that moves by rounding takes the moving obstacles' step
      // (sim/integrators.hpp).
      if (at(k - 1) == at(k)) return at(k - 1);
      const double u = (t - path[k - 1][0]) / (path[k][0] - path[k - 1][0]);
      return (1 - u) * at(k - 1) + u * at(k);
    }
  return at(path.size() - 1);
}
}  // namespace

Eigen::VectorXd obstacle_positions(const ObstacleSet& o, double t) {
  Eigen::VectorXd y(3 * o.num_points);
  int k = 0;
  for (const CapsuleObstacle& c : o.capsules) {
    const Eigen::Vector3d d = path_offset(c.path, t);
    y.segment<3>(3 * k++) = c.a + d;
    y.segment<3>(3 * k++) = c.b + d;
  }
  for (const MeshObstacle& m : o.meshes) {
    const double f = std::max(0.0, t / m.frame_dt);
    const size_t i = std::min(size_t(f), m.frames.size() - 1), j = std::min(i + 1, m.frames.size() - 1);
    const double u = i == j ? 0.0 : f - double(i);
    // A vertex at the same place in both frames stays there exactly (as in path_offset).
    for (int v = 0; v < m.frames[i].rows(); ++v, ++k) {
      if (m.frames[i].row(v) == m.frames[j].row(v)) y.segment<3>(3 * k) = m.frames[i].row(v).transpose();
      else y.segment<3>(3 * k) = ((1 - u) * m.frames[i].row(v) + u * m.frames[j].row(v)).transpose();
    }
  }
  return y;
}

MeshObstacle read_mesh_obstacle(const std::vector<std::string>& files, double frame_dt, double scale,
                                const Eigen::Vector3d& offset) {
  if (files.empty()) throw std::invalid_argument("a mesh collider needs at least one OBJ file");
  if (!(frame_dt > 0)) throw std::invalid_argument(files[0] + ": a mesh collider's frame_dt must be > 0");
  MeshObstacle m;
  m.name = files[0];
  m.frame_dt = frame_dt;
  m.scale = scale;
  m.offset = offset;
  for (const std::string& f : files) m.files.push_back(std::filesystem::absolute(f).lexically_normal().string());
  for (size_t k = 0; k < files.size(); ++k) {
    const ObjGeometry g = read_obj_geometry(files[k]);
    if (g.F.cols() == 0) throw std::invalid_argument(files[k] + ": no triangles (a mesh collider needs faces)");
    if (!g.V.allFinite()) throw std::invalid_argument(files[k] + ": non-finite vertex positions");
    Eigen::MatrixX3d x = (g.V.transpose() * scale).rowwise() + offset.transpose();
    if (k == 0) {
      m.tris = g.F.transpose();
    } else {
      if (x.rows() != m.frames[0].rows())
        throw std::invalid_argument(files[k] + ": " + std::to_string(x.rows()) + " vertices, but " + files[0] + " has " +
                                    std::to_string(m.frames[0].rows()) + " (every frame of a mesh collider has the same vertices)");
      if (Eigen::MatrixX3i(g.F.transpose()) != m.tris)
        throw std::invalid_argument(files[k] + ": its faces differ from " + files[0] + "'s (every frame has the same faces)");
    }
    m.frames.push_back(std::move(x));
  }
  return m;
}

MeshObstacle capsules_mesh(const std::vector<CapsuleObstacle>& capsules, int around, int rings) {
  if (around < 3 || rings < 1) throw std::invalid_argument("capsules_mesh: at least 3 vertices per ring and 1 ring");
  std::vector<Eigen::Vector3d> V;
  std::vector<Eigen::Vector3i> F;
  for (const CapsuleObstacle& c : capsules) {
    const Eigen::Vector3d w = (c.b - c.a).normalized();
    Eigen::Vector3d t = w.cross(std::abs(w.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()).normalized();
    const Eigen::Vector3d s = w.cross(t);  // (t, s, w) right-handed
    const int base = int(V.size());
    // The pole at a, rings from a's half sphere to b's (polar angle -pi/2 .. pi/2, the last ring
    // of a's half and the first of b's at angle 0), the pole at b.
    V.push_back(c.a - c.radius * w);
    for (int half = 0; half < 2; ++half)
      for (int k = 0; k < rings; ++k) {
        const double th = half == 0 ? -M_PI / 2 + M_PI / 2 * (k + 1) / rings : M_PI / 2 * k / rings;
        const Eigen::Vector3d centre = half == 0 ? c.a : c.b;
        for (int i = 0; i < around; ++i) {
          const double u = 2 * M_PI * i / around;
          V.push_back(centre + c.radius * (std::cos(th) * (std::cos(u) * t + std::sin(u) * s) + std::sin(th) * w));
        }
      }
    V.push_back(c.b + c.radius * w);
    const int nring = 2 * rings, top = base + 1 + nring * around;
    auto ring = [&](int r, int i) { return base + 1 + r * around + (i % around); };
    // Counterclockwise seen from outside: around the pole at a (normal -w), then the bands, then b.
    for (int i = 0; i < around; ++i) F.emplace_back(base, ring(0, i + 1), ring(0, i));
    for (int r = 0; r + 1 < nring; ++r)
      for (int i = 0; i < around; ++i) {
        F.emplace_back(ring(r, i), ring(r, i + 1), ring(r + 1, i + 1));
        F.emplace_back(ring(r, i), ring(r + 1, i + 1), ring(r + 1, i));
      }
    for (int i = 0; i < around; ++i) F.emplace_back(top, ring(nring - 1, i), ring(nring - 1, i + 1));
  }
  MeshObstacle m;
  m.name = "capsules";
  m.tris.resize(Eigen::Index(F.size()), 3);
  for (size_t k = 0; k < F.size(); ++k) m.tris.row(Eigen::Index(k)) = F[k].transpose();
  Eigen::MatrixX3d x(Eigen::Index(V.size()), 3);
  for (size_t k = 0; k < V.size(); ++k) x.row(Eigen::Index(k)) = V[k].transpose();
  m.frames = {x};
  if (!capsules.empty()) m.friction = capsules[0].friction;
  return m;
}

void write_obstacle_obj(const std::string& path, const MeshObstacle& m, size_t frame) {
  ObjWriter w(path);
  const Eigen::MatrixX3d& x = m.frames.at(frame);
  for (int v = 0; v < x.rows(); ++v) w.vertex(x(v, 0), x(v, 1), x(v, 2));
  for (int t = 0; t < m.tris.rows(); ++t) w.face({m.tris(t, 0) + 1, m.tris(t, 1) + 1, m.tris(t, 2) + 1});
  w.commit();
}

}  // namespace yarnhom::sim
