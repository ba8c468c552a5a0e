#include "accuracy/obj_read.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "core/error.hpp"

namespace yarnhom {

ObjGeometry read_obj_geometry(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FileError(path, "", "cannot open");
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector3i> f;
  ObjGeometry g;
  std::string line, group;
  int lineno = 0;
  auto fail = [&](const std::string& what) { throw FileError(path, "line " + std::to_string(lineno), what); };
  // "7", "7/3", "7//2", "7/3/2", or negative (relative to the end).
  auto index = [&](const std::string& tok) {
    int i = 0;
    try {
      i = std::stoi(tok.substr(0, tok.find('/')));
    } catch (const std::exception&) {
      fail("bad vertex index '" + tok + "'");
    }
    const int k = i > 0 ? i - 1 : int(v.size()) + i;
    if (i == 0 || k < 0 || k >= int(v.size())) fail("vertex index " + tok + " out of range");
    return k;
  };
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream ss(line);
    std::string tag;
    if (!(ss >> tag)) continue;
    if (tag == "g") {
      group.clear();
      ss >> group;  // the first name; "g" alone is the default group
    } else if (tag == "v") {
      Eigen::Vector3d p;
      if (!(ss >> p[0] >> p[1] >> p[2])) fail("a vertex needs three numbers");
      v.push_back(p);
    } else if (tag == "f" || tag == "l") {
      std::vector<int> idx;
      std::string tok;
      while (ss >> tok) idx.push_back(index(tok));
      if (tag == "l") {
        if (idx.size() < 2) fail("a polyline needs two vertices");
        g.lines.push_back(idx);
        g.line_groups.push_back(group);
      } else {
        if (idx.size() < 3) fail("a face needs three vertices");
        for (size_t k = 1; k + 1 < idx.size(); ++k) f.emplace_back(idx[0], idx[k], idx[k + 1]);
      }
    }
  }
  g.V.resize(3, v.size());
  for (size_t i = 0; i < v.size(); ++i) g.V.col(Eigen::Index(i)) = v[i];
  g.F.resize(3, f.size());
  for (size_t i = 0; i < f.size(); ++i) g.F.col(Eigen::Index(i)) = f[i];
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
