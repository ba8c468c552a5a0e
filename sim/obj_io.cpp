#include "sim/obj_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "io/obj_read.hpp"
#include "io/obj_write.hpp"

namespace yarnhom::sim {

namespace {

constexpr const char* kUvLine = "yarnhom uv: rest_m = origin + scale * vt;";

// The "# yarnhom uv:" line's origin and scale, from the comment lines before the first vertex;
// none: texture coordinates in metres (scale 1).
void read_uv_map(const std::string& path, double& ou, double& ov, double& scale) {
  ou = ov = 0;
  scale = 1;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    if (line[0] != '#') return;
    const size_t k = line.find(kUvLine);
    if (k == std::string::npos) continue;
    double a, b, c;
    if (std::sscanf(line.c_str() + k + std::string(kUvLine).size(), " origin %lf %lf scale %lf", &a, &b, &c) != 3 ||
        !std::isfinite(a) || !std::isfinite(b) || !(c > 0) || !std::isfinite(c))
      throw std::invalid_argument(path + ": malformed '# yarnhom uv:' line: " + line);
    ou = a, ov = b, scale = c;
    return;
  }
}

// The map of write_obj: origin at the rest shape's lower corner, one scale (its larger extent).
void uv_map(const Mesh& mesh, double& ou, double& ov, double& scale) {
  const Eigen::Vector2d lo = mesh.rest.colwise().minCoeff(), hi = mesh.rest.colwise().maxCoeff();
  ou = lo.x(), ov = lo.y();
  scale = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  if (!(scale > 0)) scale = 1;
}

void write_uv(ObjWriter& w, const Mesh& mesh) {
  double ou, ov, scale;
  uv_map(mesh, ou, ov, scale);
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s origin %.17g %.17g scale %.17g", kUvLine, ou, ov, scale);
  w.comment(buf);
  for (int v = 0; v < mesh.rest.rows(); ++v) w.texcoord((mesh.rest(v, 0) - ou) / scale, (mesh.rest(v, 1) - ov) / scale);
}

}  // namespace

// The mesh from the one OBJ reader (io/obj_read.hpp): every face corner must carry a texture
// coordinate (the rest position), and a vertex only one (no seams).
Mesh read_obj(const std::string& path) {
  const ObjGeometry g = read_obj_geometry(path);
  double ou, ov, scale;
  read_uv_map(path, ou, ov, scale);
  const int nv = int(g.V.cols()), nf = int(g.F.cols());
  if (nf == 0) throw std::invalid_argument(path + ": no faces");
  std::vector<int> vt_of(size_t(nv), -1);  // texture index per vertex, -1 until a face names it
  for (int t = 0; t < nf; ++t)
    for (int k = 0; k < 3; ++k) {
      const int v = g.F(k, t), u = g.FT(k, t);
      const std::string where = path + ":" + std::to_string(g.face_line[size_t(t)]);
      if (u < 0) throw std::invalid_argument(where + ": face corner without a texture coordinate (rest positions come from vt)");
      if (vt_of[v] >= 0 && vt_of[v] != u && g.T.col(vt_of[v]) != g.T.col(u))
        throw std::invalid_argument(where + ": vertex " + std::to_string(v + 1) +
                                    " has two different texture coordinates (a seam); not supported");
      vt_of[v] = u;
    }
  // Vertices that no face uses are dropped (they would be free particles).
  // The others keep their order, so that a written mesh reads back with the same numbering.
  std::vector<int> remap(size_t(nv), -1);
  for (int t = 0; t < nf; ++t)
    for (int k = 0; k < 3; ++k) remap[g.F(k, t)] = 0;
  int n = 0;
  for (int& r : remap)
    if (r == 0) r = n++;
  Mesh m;
  m.rest.resize(n, 2);
  m.x.resize(n, 3);
  for (int v = 0; v < nv; ++v)
    if (remap[v] >= 0) {
      m.x.row(remap[v]) = g.V.col(v).transpose();
      m.rest(remap[v], 0) = ou + scale * g.T(0, vt_of[v]);
      m.rest(remap[v], 1) = ov + scale * g.T(1, vt_of[v]);
    }
  m.tris.resize(nf, 3);
  for (int t = 0; t < nf; ++t)
    for (int k = 0; k < 3; ++k) m.tris(t, k) = remap[g.F(k, t)];
  finish_mesh(m, path);
  return m;
}

void write_obj(const std::string& path, const Mesh& mesh, const Eigen::MatrixX3d& x) {
  ObjWriter w(path);
  w.comment("yarnhom sim: positions (m); texture coordinates in [0, 1], the rest positions (m) mapped by:");
  write_uv(w, mesh);
  for (int v = 0; v < x.rows(); ++v) w.vertex(x(v, 0), x(v, 1), x(v, 2));
  for (int t = 0; t < mesh.num_triangles(); ++t)
    w.face_with_texcoords({mesh.tris(t, 0) + 1, mesh.tris(t, 1) + 1, mesh.tris(t, 2) + 1});
  w.commit();
}

void write_rest_obj(const std::string& path, const Mesh& mesh) {
  ObjWriter w(path);
  w.comment("yarnhom sim: the rest shape, positions (rest_u, rest_v, 0) in metres; texture coordinates as the frames':");
  write_uv(w, mesh);
  for (int v = 0; v < mesh.rest.rows(); ++v) w.vertex(mesh.rest(v, 0), mesh.rest(v, 1), 0.0);
  for (int t = 0; t < mesh.num_triangles(); ++t)
    w.face_with_texcoords({mesh.tris(t, 0) + 1, mesh.tris(t, 1) + 1, mesh.tris(t, 2) + 1});
  w.commit();
}

}  // namespace yarnhom::sim
