#include "yarn/rod/pattern.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/file_checks.hpp"
#include "yarn/rod/frames.hpp"

namespace yarnhom::yarn {
namespace {

std::string line_ref(int line) { return "line " + std::to_string(line); }

struct Block {
  std::string name;
  int header_line = 0;
  std::vector<std::vector<double>> rows;
  std::vector<int> lines;
};

// The number of fields of one row of each known block, with their names for messages.
const std::map<std::string, std::pair<int, const char*>>& block_shapes() {
  static const std::map<std::string, std::pair<int, const char*>> shapes = {
      {"pattern", {4, "px py radius n"}}, {"Q", {4, "x y z t"}},   {"E", {4, "v0 v1 dx dy"}},
      {"RL", {1, "rest length"}},          {"RK", {2, "k1 k2"}},    {"RT", {1, "rest twist"}},
      {"RefD1", {3, "dx dy dz"}},          {"RefT", {1, "reference twist"}}};
  return shapes;
}

bool parse_number(const std::string& s, double& out) {
  const char* b = s.c_str();
  char* end = nullptr;
  out = std::strtod(b, &end);
  return end != b && *end == '\0';
}

bool is_integer(double v) { return std::isfinite(v) && v == std::round(v); }

using Blocks = std::map<std::string, Block>;

[[noreturn]] void fail(const std::string& file, int line, const std::string& problem) {
  throw FileError(file, line > 0 ? line_ref(line) : "", problem);
}

// The text's blocks: each header line `*name` and the rows of numbers after it, checked
// against the block's shape.
Blocks read_blocks(const std::string& text, const std::string& file) {
  Blocks blocks;
  Block* cur = nullptr;
  std::istringstream in(text);
  std::string raw;
  int lineno = 0;
  while (std::getline(in, raw)) {
    ++lineno;
    std::string line = raw.substr(0, raw.find('#'));
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
      line.pop_back();
    size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos) continue;  // blank lines separate blocks; nothing to do
    line = line.substr(start);
    if (line[0] == '*') {
      std::istringstream hs(line.substr(1));
      std::string name;
      hs >> name;
      if (!block_shapes().count(name)) {
        std::string known;
        for (auto& [k, v] : block_shapes()) known += (known.empty() ? "*" : ", *") + k;
        fail(file, lineno, "unknown block '*" + name + "' (known: " + known + ")");
      }
      if (blocks.count(name))
        fail(file, lineno, "block '*" + name + "' appears twice (first at line " +
                               std::to_string(blocks[name].header_line) + ")");
      cur = &blocks[name];
      cur->name = name;
      cur->header_line = lineno;
      continue;
    }
    if (!cur) fail(file, lineno, "data before any block header (a line starting with '*')");
    std::istringstream ls(line);
    std::vector<double> row;
    std::string field;
    int k = 0;
    while (ls >> field) {
      ++k;
      double v;
      if (!parse_number(field, v) || !std::isfinite(v))
        fail(file, lineno, "field " + std::to_string(k) + " '" + field + "' of *" + cur->name +
                               " is not a finite number");
      row.push_back(v);
    }
    const auto& shape = block_shapes().at(cur->name);
    if (static_cast<int>(row.size()) != shape.first)
      fail(file, lineno, "*" + cur->name + " expects " + std::to_string(shape.first) + " fields (" +
                             shape.second + "), got " + std::to_string(row.size()));
    cur->rows.push_back(std::move(row));
    cur->lines.push_back(lineno);
  }
  return blocks;
}

// *pattern: the periods, the radius and the vertex count n.
int read_header(const Blocks& blocks, const std::string& file, Pattern& p) {
  const Block& hb = blocks.at("pattern");
  if (hb.rows.size() != 1)
    fail(file, hb.header_line, "*pattern must have exactly one line (px py radius n), has " +
                                   std::to_string(hb.rows.size()));
  const auto& r = hb.rows[0];
  p.px = r[0];
  p.py = r[1];
  p.radius = r[2];
  if (!(p.px > 0 && p.py > 0 && p.radius > 0))
    fail(file, hb.lines[0], "px, py and radius must be positive");
  // Bounds that no textile breaks but a broken or mis-scaled file does (a radius of 1 m or
  // 1e-30 m used to run minutes of rest relaxation, or produce Psi ~ 1e-76): see
  // kPatternRules in pattern.hpp.
  if (!(p.radius >= kMinRadius && p.radius <= kMaxRadius))
    fail(file, hb.lines[0], "radius " + std::to_string(p.radius) + " m is outside [1e-6, 1e-2] m (a yarn radius, in metres)");
  if (!(p.px >= 2 * p.radius && p.py >= 2 * p.radius && p.px <= 1000 * p.radius && p.py <= 1000 * p.radius))
    fail(file, hb.lines[0], "the periods px and py must lie between 2 and 1000 yarn radii");
  if (!is_integer(r[3]) || r[3] < 2 || r[3] > kMaxVertices)
    fail(file, hb.lines[0], "n must be an integer in 2.." + std::to_string(kMaxVertices) + ", got " + std::to_string(r[3]));
  return static_cast<int>(r[3]);
}

// Whether block `name` is there (a required one must be) with n entries.
bool check_count(const Blocks& blocks, const std::string& file, const char* name, bool required, int n) {
  if (!blocks.count(name)) {
    if (required) fail(file, 0, std::string("missing block *") + name);
    return false;
  }
  const Block& b = blocks.at(name);
  if (static_cast<int>(b.rows.size()) != n)
    fail(file, b.header_line, std::string("*") + name + " has " + std::to_string(b.rows.size()) +
                                  " entries, *pattern (line " + std::to_string(blocks.at("pattern").lines[0]) +
                                  ") says " + std::to_string(n));
  return true;
}

// *Q: positions and twist angles.
void read_vertices(const Block& qb, const std::string& file, Pattern& p) {
  for (size_t i = 0; i < qb.rows.size(); ++i) {
    const auto& r = qb.rows[i];
    if (!(std::abs(r[0]) <= 10 * p.px && std::abs(r[1]) <= 10 * p.py && std::abs(r[2]) <= 100 * p.radius))
      fail(file, qb.lines[i], "vertex outside the tile's neighbourhood (|x| <= 10 px, |y| <= 10 py, |z| <= 100 radii)");
    if (!(std::abs(r[3]) <= kMaxAngle))
      fail(file, qb.lines[i], "twist angle t = " + std::to_string(r[3]) + " rad: must lie within +-100 rad (16 turns; "
                              "larger angles lose all precision in cos and sin)");
    p.x.emplace_back(r[0], r[1], r[2]);
    p.theta.push_back(r[3]);
  }
}

// *E: the edges. With n edges and no vertex having two outgoing or two incoming ones, every
// vertex has exactly one of each: the yarns are closed.
void read_edges(const Block& eb, const std::string& file, int n, Pattern& p) {
  std::vector<int> out_line(n, 0), in_line(n, 0);
  for (size_t i = 0; i < eb.rows.size(); ++i) {
    const auto& r = eb.rows[i];
    const int line = eb.lines[i];
    for (int k = 0; k < 4; ++k)
      if (!is_integer(r[k])) fail(file, line, "edge field " + std::to_string(k + 1) + " must be an integer");
    // Ranges are checked on the numbers as read, before they become ints (1e300 is an
    // integer-valued double that no int holds).
    for (int k = 0; k < 2; ++k)
      if (r[k] < 0 || r[k] >= n) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%g", r[k]);
        fail(file, line, std::string("edge to missing vertex ") + buf + " (vertices are 0.." + std::to_string(n - 1) + ")");
      }
    if (r[2] < -1 || r[2] > 1 || r[3] < -1 || r[3] > 1) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "offsets dx=%g dy=%g outside -1..1", r[2], r[3]);
      fail(file, line, buf);
    }
    PatternEdge e{int(r[0]), int(r[1]), int(r[2]), int(r[3])};
    if (out_line[e.v0])
      fail(file, line, "vertex " + std::to_string(e.v0) + " already has an outgoing edge (line " +
                           std::to_string(out_line[e.v0]) + "); yarns must be simple closed chains");
    if (in_line[e.v1])
      fail(file, line, "vertex " + std::to_string(e.v1) + " already has an incoming edge (line " +
                           std::to_string(in_line[e.v1]) + "); yarns must be simple closed chains");
    out_line[e.v0] = in_line[e.v1] = line;
    const Eigen::Vector3d ev = p.x[e.v1] + Eigen::Vector3d(e.dx * p.px, e.dy * p.py, 0) - p.x[e.v0];
    if (ev.norm() <= 1e-9 * p.radius)
      fail(file, line, "zero-length edge " + std::to_string(e.v0) + " -> " + std::to_string(e.v1));
    if (!(ev.norm() >= kMinEdge * p.radius && ev.norm() <= kMaxEdge * p.radius))
      fail(file, line, "edge " + std::to_string(e.v0) + " -> " + std::to_string(e.v1) + " is " +
                           std::to_string(ev.norm() / p.radius) + " yarn radii long: must be 0.01..100 radii");
    p.edges.push_back(e);
  }
}

// The rest-state blocks *RL *RK *RT *RefD1 *RefT (all present).
void read_rest_state(const Blocks& blocks, const std::string& file, int n, Pattern& p) {
  // Edge vector of each vertex's outgoing edge, for the rest-length and director rules.
  std::vector<Eigen::Vector3d> out_edge(n);
  for (const auto& e : p.edges)
    out_edge[e.v0] = p.x[e.v1] + Eigen::Vector3d(e.dx * p.px, e.dy * p.py, 0) - p.x[e.v0];
  const Block& rl = blocks.at("RL");
  for (size_t i = 0; i < rl.rows.size(); ++i) {
    const double L = rl.rows[i][0], ratio = L / out_edge[i].norm();
    if (!(L > 0)) fail(file, rl.lines[i], "rest length must be positive");
    if (!(L >= kMinEdge * p.radius && L <= kMaxEdge * p.radius && ratio >= 0.1 && ratio <= 10))
      fail(file, rl.lines[i], "rest length " + std::to_string(L) + " m: must be 0.01..100 yarn radii and 0.1..10 "
                              "times the stored length of its edge");
    p.rest_length.push_back(L);
  }
  const Block& kb = blocks.at("RK");
  for (size_t i = 0; i < kb.rows.size(); ++i) {
    const auto& r = kb.rows[i];
    if (!(std::abs(r[0]) <= kMaxRestCurvature && std::abs(r[1]) <= kMaxRestCurvature))
      fail(file, kb.lines[i], "rest curvature beyond +-10 (a turning angle of more than 157 degrees at one joint)");
    p.rest_kappa.emplace_back(r[0], r[1]);
  }
  const Block& tb = blocks.at("RT");
  for (size_t i = 0; i < tb.rows.size(); ++i) {
    if (!(std::abs(tb.rows[i][0]) <= 2 * M_PI)) fail(file, tb.lines[i], "rest twist beyond +-2 pi rad at one joint");
    p.rest_twist.push_back(tb.rows[i][0]);
  }
  const Block& db = blocks.at("RefD1");
  for (size_t i = 0; i < db.rows.size(); ++i) {
    Eigen::Vector3d d(db.rows[i][0], db.rows[i][1], db.rows[i][2]);
    if (d.norm() < 1e-6) fail(file, db.lines[i], "reference director has zero length");
    if (!(std::abs(d.normalized().dot(out_edge[i].normalized())) <= 0.9))
      fail(file, db.lines[i], "reference director (nearly) parallel to its edge: it must be at least 25 degrees "
                              "away from the edge (ideally perpendicular)");
    p.ref_d1.push_back(d);
  }
  const Block& rb = blocks.at("RefT");
  for (size_t i = 0; i < rb.rows.size(); ++i) {
    if (!(std::abs(rb.rows[i][0]) <= 2 * M_PI)) fail(file, rb.lines[i], "reference twist beyond +-2 pi rad");
    p.ref_twist.push_back(rb.rows[i][0]);
  }
}

}  // namespace

Pattern parse_pyp(const std::string& text, const std::string& file) {
  const Blocks blocks = read_blocks(text, file);
  for (const char* req : {"pattern", "Q", "E"})
    if (!blocks.count(req)) fail(file, 0, std::string("missing block *") + req);
  Pattern p;
  const int n = read_header(blocks, file, p);
  check_count(blocks, file, "Q", true, n);
  check_count(blocks, file, "E", true, n);
  read_vertices(blocks.at("Q"), file, p);
  read_edges(blocks.at("E"), file, n, p);
  const bool have[5] = {check_count(blocks, file, "RL", false, n), check_count(blocks, file, "RK", false, n),
                        check_count(blocks, file, "RT", false, n), check_count(blocks, file, "RefD1", false, n),
                        check_count(blocks, file, "RefT", false, n)};
  const int nhave = have[0] + have[1] + have[2] + have[3] + have[4];
  if (nhave == 0) {
    complete_rest_state(p);
  } else if (nhave != 5) {
    fail(file, 0, "the rest-state blocks *RL *RK *RT *RefD1 *RefT must be all present or all absent");
  } else {
    read_rest_state(blocks, file, n, p);
  }
  return p;
}

Pattern read_pyp(const std::string& path) {
  check_input_file(path);
  // The largest paper pattern is 30 kB; a million vertices with every block is ~150 MB.
  if (std::filesystem::file_size(path) > (size_t(256) << 20))
    throw FileError(path, "", "larger than 256 MiB: not a pattern file");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw FileError(path, "", "cannot open for reading");
  std::stringstream ss;
  ss << f.rdbuf();
  Pattern p = parse_pyp(ss.str(), path);
  std::string stem = path.substr(path.find_last_of('/') + 1);
  p.name = stem.substr(0, stem.rfind('.'));
  p.source = path;
  return p;
}

std::string format_pyp(const Pattern& p) {
  std::string s;
  char buf[256];
  auto add = [&](const char* fmt, auto... a) {
    std::snprintf(buf, sizeof buf, fmt, a...);
    s += buf;
  };
  const int n = p.size();
  s += "*pattern # px py radius num_vertedges\n";
  add("%.17g %.17g %.17g %d\n\n", p.px, p.py, p.radius, n);
  s += "*Q # dofs: x y z t\n";
  for (int i = 0; i < n; ++i) add("%.17g %.17g %.17g %.17g\n", p.x[i][0], p.x[i][1], p.x[i][2], p.theta[i]);
  s += "\n*E # edges: v0 v1 dx dy\n";
  for (const auto& e : p.edges) add("%d %d %d %d\n", e.v0, e.v1, e.dx, e.dy);
  s += "\n*RL # rest lengths\n";
  for (double v : p.rest_length) add("%.17g\n", v);
  s += "\n*RK # rest kappas\n";
  for (const auto& k : p.rest_kappa) add("%.17g %.17g\n", k[0], k[1]);
  s += "\n*RT # rest twists\n";
  for (double v : p.rest_twist) add("%.17g\n", v);
  s += "\n*RefD1 # reference directors\n";
  for (const auto& d : p.ref_d1) add("%.17g %.17g %.17g\n", d[0], d[1], d[2]);
  s += "\n*RefT # reference twists\n";
  for (double v : p.ref_twist) add("%.17g\n", v);
  return s;
}

void write_pyp(const std::string& path, const Pattern& p) {
  AtomicOutput out(path);
  {
    std::ofstream f(out.temp_path(), std::ios::binary);
    if (!f) throw FileError(path, "", "cannot open for writing");
    f << format_pyp(p);
    if (!f) throw FileError(path, "", "write failed");
  }
  out.commit();
}

Topology topology(const Pattern& p) {
  const int n = p.size();
  Topology t;
  t.next.assign(n, -1);
  t.prev.assign(n, -1);
  t.offset.assign(n, Eigen::Vector2i::Zero());
  for (const auto& e : p.edges) {
    t.next[e.v0] = e.v1;
    t.prev[e.v1] = e.v0;
    t.offset[e.v0] = Eigen::Vector2i(e.dx, e.dy);
  }
  t.yarn_of.assign(n, -1);
  for (int s = 0; s < n; ++s) {
    if (t.yarn_of[s] >= 0) continue;
    std::vector<int> yarn;
    for (int v = s; t.yarn_of[v] < 0; v = t.next[v]) {
      t.yarn_of[v] = static_cast<int>(t.yarns.size());
      yarn.push_back(v);
    }
    t.yarns.push_back(std::move(yarn));
  }
  return t;
}

Eigen::Vector3d stored_edge(const Pattern& p, const Topology& t, int v) {
  const Eigen::Vector2i o = t.offset[v];
  return p.x[t.next[v]] + Eigen::Vector3d(o[0] * p.px, o[1] * p.py, 0) - p.x[v];
}

void complete_rest_state(Pattern& p) {
  const Topology t = topology(p);
  const int n = p.size();
  p.rest_length.assign(n, 0);
  p.rest_kappa.assign(n, Eigen::Vector2d::Zero());
  p.rest_twist.assign(n, 0);
  p.ref_d1.assign(n, Eigen::Vector3d::Zero());
  p.ref_twist.assign(n, 0);
  for (int v = 0; v < n; ++v) p.rest_length[v] = stored_edge(p, t, v).norm();
  for (const auto& yarn : t.yarns) {
    // First director: any unit vector perpendicular to the first tangent; the rest follow by
    // space-parallel transport, so the reference twist is zero except at the closing joint.
    const Eigen::Vector3d t0 = stored_edge(p, t, yarn[0]).normalized();
    Eigen::Vector3d a = std::abs(t0[2]) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    p.ref_d1[yarn[0]] = (a - a.dot(t0) * t0).normalized();
    for (size_t k = 1; k < yarn.size(); ++k) {
      const int v = yarn[k], u = yarn[k - 1];
      const V3<double> ta(stored_edge(p, t, u).normalized()), tb(stored_edge(p, t, v).normalized());
      const V3<double> d = transport_same(ta, tb, V3<double>(p.ref_d1[u]));
      p.ref_d1[v] = Eigen::Vector3d(d.x, d.y, d.z).normalized();
    }
    for (int v : yarn) {
      const int u = t.prev[v];
      const V3<double> ta(stored_edge(p, t, u).normalized()), tb(stored_edge(p, t, v).normalized());
      const V3<double> moved = transport_same(ta, tb, V3<double>(p.ref_d1[u]));
      p.ref_twist[v] = signed_angle(moved, V3<double>(p.ref_d1[v]), tb);
    }
  }
}

Pattern tile(const Pattern& p, int nx, int ny) {
  const Topology t = topology(p);
  const int n = p.size();
  Pattern q;
  q.name = p.name + "_" + std::to_string(nx) + "x" + std::to_string(ny);
  q.px = p.px * nx;
  q.py = p.py * ny;
  q.radius = p.radius;
  auto id = [&](int v, int i, int j) { return (j * nx + i) * n + v; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      for (int v = 0; v < n; ++v) {
        // Centre the big tile like the small one: shift copies around the origin.
        q.x.push_back(p.x[v] + Eigen::Vector3d((i - 0.5 * (nx - 1)) * p.px, (j - 0.5 * (ny - 1)) * p.py, 0));
        q.theta.push_back(p.theta[v]);
        q.rest_length.push_back(p.rest_length[v]);
        q.rest_kappa.push_back(p.rest_kappa[v]);
        q.rest_twist.push_back(p.rest_twist[v]);
        q.ref_d1.push_back(p.ref_d1[v]);
        q.ref_twist.push_back(p.ref_twist[v]);
      }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      for (int v = 0; v < n; ++v) {
        const int w = t.next[v];
        const int ti = i + t.offset[v][0], tj = j + t.offset[v][1];
        const int wi = ((ti % nx) + nx) % nx, wj = ((tj % ny) + ny) % ny;
        q.edges.push_back({id(v, i, j), id(w, wi, wj), (ti - wi) / nx, (tj - wj) / ny});
      }
  return q;
}

}  // namespace yarnhom::yarn
