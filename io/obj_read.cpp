#include "io/obj_read.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/file_checks.hpp"

namespace yarnhom {

namespace {

struct Parser {
  std::string path;
  int lineno = 0;
  [[noreturn]] void fail(const std::string& what) const {
    throw FileError(path + ":" + std::to_string(lineno), "", what);
  }
  // One index of a corner: 1-based, or negative counting back from the end; `count` defined so far.
  int index(const std::string& s, int count, const char* what) const {
    size_t used = 0;
    long k = 0;
    try {
      k = std::stol(s, &used);
    } catch (const std::exception&) {
      fail(std::string("bad ") + what + " index '" + s + "'");
    }
    if (used != s.size() || k == 0) fail(std::string("bad ") + what + " index '" + s + "'");
    const long i = k > 0 ? k - 1 : count + k;
    if (i < 0 || i >= count)
      fail(std::string(what) + " index " + s + " out of range (" + std::to_string(count) + " defined so far)");
    return int(i);
  }
  // "12", "12/4", "12/4/7", "12//7": the vertex and the texture index (-1 when absent).
  void corner(const std::string& tok, int nv, int nt, int& v, int& t) const {
    const size_t s1 = tok.find('/');
    v = index(tok.substr(0, s1), nv, "vertex");
    t = -1;
    if (s1 == std::string::npos) return;
    const size_t s2 = tok.find('/', s1 + 1);
    const std::string ts = tok.substr(s1 + 1, s2 == std::string::npos ? std::string::npos : s2 - s1 - 1);
    if (!ts.empty()) t = index(ts, nt, "texture");
  }
};

}  // namespace

ObjGeometry read_obj_geometry(const std::string& path) {
  check_input_file(path);  // a FIFO would block the reader
  std::ifstream in(path);
  if (!in) throw FileError(path, "", "cannot open");
  Parser P{path};
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector2d> vt;
  std::vector<Eigen::Vector3i> f, ft;
  ObjGeometry g;
  std::string line, group;
  while (std::getline(in, line)) {
    ++P.lineno;
    std::istringstream ss(line);
    std::string tag;
    if (!(ss >> tag) || tag[0] == '#') continue;
    if (tag == "g") {
      group.clear();
      ss >> group;  // the first name; "g" alone is the default group
    } else if (tag == "v") {
      Eigen::Vector3d p;
      if (!(ss >> p[0] >> p[1] >> p[2]) || !p.allFinite()) P.fail("bad vertex line (a vertex needs three finite numbers)");
      v.push_back(p);
    } else if (tag == "vt") {
      Eigen::Vector2d u;
      if (!(ss >> u[0] >> u[1]) || !u.allFinite()) P.fail("bad texture coordinate line");
      vt.push_back(u);
    } else if (tag == "f" || tag == "l") {
      std::vector<int> idx, tex;
      std::string tok;
      while (ss >> tok) {
        int a, b;
        P.corner(tok, int(v.size()), int(vt.size()), a, b);
        idx.push_back(a);
        tex.push_back(b);
      }
      if (tag == "l") {
        if (idx.size() < 2) P.fail("a polyline needs two vertices");
        g.lines.push_back(idx);
        g.line_groups.push_back(group);
        continue;
      }
      if (idx.size() < 3) P.fail("face with fewer than 3 corners");
      for (size_t k = 1; k + 1 < idx.size(); ++k) {
        f.emplace_back(idx[0], idx[k], idx[k + 1]);
        ft.emplace_back(tex[0], tex[k], tex[k + 1]);
        g.face_line.push_back(P.lineno);
      }
    }
  }
  g.V.resize(3, Eigen::Index(v.size()));
  for (size_t i = 0; i < v.size(); ++i) g.V.col(Eigen::Index(i)) = v[i];
  g.T.resize(2, Eigen::Index(vt.size()));
  for (size_t i = 0; i < vt.size(); ++i) g.T.col(Eigen::Index(i)) = vt[i];
  g.F.resize(3, Eigen::Index(f.size()));
  g.FT.resize(3, Eigen::Index(f.size()));
  for (size_t i = 0; i < f.size(); ++i) {
    g.F.col(Eigen::Index(i)) = f[i];
    g.FT.col(Eigen::Index(i)) = ft[i];
  }
  return g;
}

Eigen::Matrix3Xd points_outside_group(const ObjGeometry& g, const std::string& group) {
  std::vector<char> keep(size_t(g.V.cols()), 0);
  bool any = false;
  for (size_t l = 0; l < g.lines.size(); ++l) {
    if (g.line_groups[l] == group) {
      any = true;
      continue;
    }
    for (int i : g.lines[l]) keep[size_t(i)] = 1;
  }
  if (!any) return g.V;
  Eigen::Matrix3Xd P(3, std::count(keep.begin(), keep.end(), 1));
  for (Eigen::Index i = 0, k = 0; i < g.V.cols(); ++i)
    if (keep[size_t(i)]) P.col(k++) = g.V.col(i);
  return P;
}

}  // namespace yarnhom
