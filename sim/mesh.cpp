#include "sim/mesh.hpp"

#include <stdexcept>
#include <unordered_map>

namespace yarnhom::sim {

void build_flaps(Mesh& mesh, const std::string& where) {
  const int n = mesh.num_vertices(), m = mesh.num_triangles();
  // Directed edge (a -> b) to (triangle, local edge). A manifold oriented mesh uses each
  // directed edge at most once, and an interior edge once in each direction.
  std::unordered_map<long long, long long> directed;
  directed.reserve(size_t(3) * m);
  auto key = [n](int a, int b) { return (long long)a * n + b; };
  for (int t = 0; t < m; ++t)
    for (int i = 0; i < 3; ++i) {
      const int a = mesh.tris(t, i), b = mesh.tris(t, (i + 1) % 3);
      if (a < 0 || a >= n || b < 0 || b >= n)
        throw std::invalid_argument(where + ": triangle " + std::to_string(t) + " has a vertex index out of range");
      if (a == b) throw std::invalid_argument(where + ": triangle " + std::to_string(t) + " repeats a vertex");
      if (!directed.emplace(key(a, b), (long long)t * 3 + i).second)
        throw std::invalid_argument(where + ": edge " + std::to_string(a) + "-" + std::to_string(b) +
                                    " is used by two triangles in the same direction (not an oriented manifold: "
                                    "inconsistent orientation or a non-manifold edge)");
    }
  mesh.flaps.resize(m, 3);
  for (int t = 0; t < m; ++t)
    for (int i = 0; i < 3; ++i) {
      const int a = mesh.tris(t, i), b = mesh.tris(t, (i + 1) % 3);
      auto it = directed.find(key(b, a));
      if (it == directed.end()) {
        mesh.flaps(t, i) = -1;
      } else {
        const int u = int(it->second / 3), j = int(it->second % 3);
        mesh.flaps(t, i) = mesh.tris(u, (j + 2) % 3);
      }
    }
}

void finish_mesh(Mesh& mesh, const std::string& where) {
  const int n = mesh.num_vertices(), m = mesh.num_triangles();
  if (n < 3 || m < 1) throw std::invalid_argument(where + ": needs at least one triangle");
  if (mesh.x.rows() != n) throw std::invalid_argument(where + ": positions and rest positions differ in count");
  if (!mesh.rest.allFinite() || !mesh.x.allFinite())
    throw std::invalid_argument(where + ": non-finite coordinate");
  int cw = 0, ccw = 0;
  for (int t = 0; t < m; ++t) {
    const Eigen::Vector2d u0 = mesh.rest.row(mesh.tris(t, 0)), u1 = mesh.rest.row(mesh.tris(t, 1)),
                          u2 = mesh.rest.row(mesh.tris(t, 2));
    const double det = (u1 - u0).x() * (u2 - u0).y() - (u1 - u0).y() * (u2 - u0).x();
    if (det > 0) ++ccw;
    else if (det < 0) ++cw;
    else throw std::invalid_argument(where + ": triangle " + std::to_string(t) + " has zero rest area");
  }
  if (cw && ccw)
    throw std::invalid_argument(where + ": the rest (texture) coordinates fold over: " + std::to_string(cw) +
                                " triangles are clockwise and " + std::to_string(ccw) + " counterclockwise");
  if (cw)
    for (int t = 0; t < m; ++t) std::swap(mesh.tris(t, 1), mesh.tris(t, 2));
  build_flaps(mesh, where);
}

Eigen::VectorXd vertex_areas(const Mesh& mesh) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    const Eigen::Vector2d u0 = mesh.rest.row(mesh.tris(t, 0)), u1 = mesh.rest.row(mesh.tris(t, 1)),
                          u2 = mesh.rest.row(mesh.tris(t, 2));
    const double area = 0.5 * std::abs((u1 - u0).x() * (u2 - u0).y() - (u1 - u0).y() * (u2 - u0).x());
    for (int i = 0; i < 3; ++i) a[mesh.tris(t, i)] += area / 3.0;
  }
  return a;
}

}  // namespace yarnhom::sim
