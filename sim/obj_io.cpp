#include "sim/obj_io.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/atomic_file.hpp"

namespace yarnhom::sim {

namespace {

// "12", "12/4", "12/4/7", "12//7"; negative indices count from the end (OBJ's rule).
void parse_corner(const std::string& tok, int nv, int nt, int& v, int& t, const std::string& where) {
  const size_t s1 = tok.find('/');
  auto index = [&](const std::string& s, int count, const char* what) {
    size_t used = 0;
    long k;
    try {
      k = std::stol(s, &used);
    } catch (const std::exception&) {
      throw std::invalid_argument(where + ": bad " + what + " index '" + s + "'");
    }
    if (used != s.size() || k == 0) throw std::invalid_argument(where + ": bad " + what + " index '" + s + "'");
    const long i = k > 0 ? k - 1 : count + k;
    if (i < 0 || i >= count)
      throw std::invalid_argument(where + ": " + what + " index " + s + " out of range (" + std::to_string(count) + " defined so far)");
    return int(i);
  };
  v = index(tok.substr(0, s1), nv, "vertex");
  t = -1;
  if (s1 != std::string::npos) {
    const size_t s2 = tok.find('/', s1 + 1);
    const std::string ts = tok.substr(s1 + 1, s2 == std::string::npos ? std::string::npos : s2 - s1 - 1);
    if (!ts.empty()) t = index(ts, nt, "texture");
  }
}

}  // namespace

Mesh read_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open");
  std::vector<Eigen::Vector3d> pos;
  std::vector<Eigen::Vector2d> tex;
  std::vector<Eigen::Vector3i> tris;
  std::vector<int> vt_of;  // texture index per vertex, -1 until a face names it
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    const std::string where = path + ":" + std::to_string(lineno);
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      Eigen::Vector3d p;
      if (!(ls >> p.x() >> p.y() >> p.z()) || !p.allFinite()) throw std::invalid_argument(where + ": bad vertex line");
      pos.push_back(p);
    } else if (tag == "vt") {
      Eigen::Vector2d u;
      if (!(ls >> u.x() >> u.y()) || !u.allFinite()) throw std::invalid_argument(where + ": bad texture coordinate line");
      tex.push_back(u);
    } else if (tag == "f") {
      std::vector<int> vs;
      std::string tok;
      while (ls >> tok) {
        int v, t;
        parse_corner(tok, int(pos.size()), int(tex.size()), v, t, where);
        if (t < 0) throw std::invalid_argument(where + ": face corner without a texture coordinate (rest positions come from vt)");
        if (vt_of.size() < pos.size()) vt_of.resize(pos.size(), -1);
        if (vt_of[v] >= 0 && vt_of[v] != t && tex[vt_of[v]] != tex[t])
          throw std::invalid_argument(where + ": vertex " + std::to_string(v + 1) +
                                      " has two different texture coordinates (a seam); not supported");
        vt_of[v] = t;
        vs.push_back(v);
      }
      if (vs.size() < 3) throw std::invalid_argument(where + ": face with fewer than 3 corners");
      for (size_t k = 1; k + 1 < vs.size(); ++k) tris.emplace_back(vs[0], vs[k], vs[k + 1]);
    }
  }
  if (tris.empty()) throw std::invalid_argument(path + ": no faces");
  vt_of.resize(pos.size(), -1);
  // Vertices that no face uses are dropped (they would be free particles).
  // The others keep their order, so that a written mesh reads back with the same numbering.
  std::vector<int> remap(pos.size(), -1);
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) remap[t[k]] = 0;
  int n = 0;
  for (int& r : remap)
    if (r == 0) r = n++;
  Mesh m;
  m.rest.resize(n, 2);
  m.x.resize(n, 3);
  for (size_t v = 0; v < pos.size(); ++v)
    if (remap[v] >= 0) {
      m.x.row(remap[v]) = pos[v];
      m.rest.row(remap[v]) = tex[vt_of[v]];
    }
  m.tris.resize(int(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) m.tris(int(t), k) = remap[tris[t][k]];
  finish_mesh(m, path);
  return m;
}

void write_obj(const std::string& path, const Mesh& mesh, const Eigen::MatrixX3d& x) {
  AtomicOutput out(path);
  FILE* f = std::fopen(out.temp_path().c_str(), "w");
  if (!f) throw std::invalid_argument(path + ": cannot write");
  std::fprintf(f, "# yarnhom sim: positions (m); texture coordinates = rest positions (m)\n");
  for (int v = 0; v < x.rows(); ++v) std::fprintf(f, "v %.9g %.9g %.9g\n", x(v, 0), x(v, 1), x(v, 2));
  for (int v = 0; v < mesh.rest.rows(); ++v) std::fprintf(f, "vt %.9g %.9g\n", mesh.rest(v, 0), mesh.rest(v, 1));
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    const int a = mesh.tris(t, 0) + 1, b = mesh.tris(t, 1) + 1, c = mesh.tris(t, 2) + 1;
    std::fprintf(f, "f %d/%d %d/%d %d/%d\n", a, a, b, b, c, c);
  }
  const bool ok = std::fclose(f) == 0;
  if (!ok) throw std::invalid_argument(path + ": write failed");
  out.commit();
}

}  // namespace yarnhom::sim
