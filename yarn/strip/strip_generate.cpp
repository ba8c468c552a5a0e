#include "yarn/strip/strip_generate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "yarn/rod/frames.hpp"
#include "yarn/rod/rod.hpp"
#include "yarn/strip/strip_route.hpp"

namespace yarnhom::yarn {

namespace {

long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
long floor_mod(long a, long b) { return a - b * floor_div(a, b); }

// One closed yarn of the tile, unrolled over one period.
struct TileYarn {
  std::vector<int> v;                 // pattern vertices along the yarn
  std::vector<Eigen::Vector2i> cell;  // tile cell of each, relative to the first
  Eigen::Vector2i period;             // cell offset after one period
  int dir = 0;                        // 0: runs along x, 1: along y
  double centre = 0;                  // mean across coordinate over one period (m)
};

// A row: one copy of a tile yarn in the tiling, an infinite yarn indexed by k (vertex k is
// pattern vertex v[k mod m] in cell cell[k mod m] + floor(k/m) period + the copy's shift).
struct Row {
  int yarn = 0, copy = 0;
  double centre = 0;
  bool soft = false;
  long k_first = 0, k_last = 0;  // kept range
  int sign = 1;                  // traversal: +1 along increasing axis coordinate
};

struct Tiling {
  const Pattern& p;
  Eigen::Matrix2d A;  // lattice vectors (columns)
  std::vector<TileYarn> yarns;

  Eigen::Vector2i shift(const Row& r) const {
    return yarns[r.yarn].dir == 0 ? Eigen::Vector2i(0, r.copy) : Eigen::Vector2i(r.copy, 0);
  }
  StripSource source(const Row& r, long k) const {
    const TileYarn& t = yarns[r.yarn];
    const long m = static_cast<long>(t.v.size());
    const long idx = floor_mod(k, m), q = floor_div(k, m);
    const Eigen::Vector2i c = t.cell[idx] + int(q) * t.period + shift(r);
    return {t.v[idx], c[0], c[1]};
  }
  Eigen::Vector3d position(const StripSource& s) const {
    const Eigen::Vector2d o = A * Eigen::Vector2d(s.cell_x, s.cell_y);
    return p.x[s.vertex] + Eigen::Vector3d(o[0], o[1], 0);
  }
  Eigen::Vector3d position(const Row& r, long k) const { return position(source(r, k)); }
  // +1 when increasing k moves along +axis.
  int k_sign(const Row& r) const {
    const TileYarn& t = yarns[r.yarn];
    return t.period[t.dir] > 0 ? 1 : -1;
  }
};

// A vertex of the assembled yarn before the rest state is computed.
struct PathVertex {
  Eigen::Vector3d x;
  StripSource src;
  int row = -1;   // row index (kept or continuation vertex), -1 for bridge vertices
  long k = 0;
  bool exit = false;  // a row's continuation beyond its end (boundary yarn)
};

// Points of a connector leg from a to b, spaced at most h, excluding a, including b.
void leg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double h, std::vector<Eigen::Vector3d>& out) {
  const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / h)));
  for (int i = 1; i <= n; ++i) out.push_back(a + (b - a) * (double(i) / n));
}

Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& t) {
  const Eigen::Vector3d a = std::abs(t[2]) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  return (a - a.dot(t) * t).normalized();
}

}  // namespace

StripTile as_tile(const Pattern& p) {
  StripTile t;
  t.pattern = p;
  t.lattice = Eigen::Vector2d(p.px, p.py).asDiagonal();
  return t;
}

StripTile rest_tile(const Pattern& raw, const Material& material, const RestOptions& opt) {
  const RestTile rt = relax_tile(raw, material, opt);
  const RveProblem& rve = rt.rve;
  StripTile t;
  t.lattice = rve.lattice();
  Pattern& q = t.pattern;
  q = rve.pattern();
  q.px = t.lattice(0, 0);
  q.py = t.lattice(1, 1);
  // At s = 0 the RVE's map is the identity on its reference coordinates (F0 applied to the
  // stored points first): positions and frames there are the tile's geometry at rest.
  q.x = rve.positions(Strain::Zero(), rt.state);
  q.theta = rt.state.theta;
  const Topology& topo = rve.topo();
  auto edge = [&](int v) {
    const Eigen::Vector2d o = t.lattice * topo.offset[v].cast<double>();
    return (q.x[topo.next[v]] + Eigen::Vector3d(o[0], o[1], 0) - q.x[v]).normalized();
  };
  for (int v = 0; v < q.size(); ++v) q.ref_d1[v] = transported_director(rt.state.frames.edge[v], edge(v));
  for (int v = 0; v < q.size(); ++v) {
    const int a = topo.prev[v];
    q.ref_twist[v] = reference_twist(edge(a), q.ref_d1[a], edge(v), q.ref_d1[v], rt.state.frames.twist[v]);
  }
  return t;
}

namespace {

[[noreturn]] void fail(const Pattern& p, const std::string& what) {
  throw std::invalid_argument("strip of pattern '" + p.name + "': " + what);
}

// Step 1: the tile's yarns, unrolled over one period each.
Tiling make_tiling(const StripTile& tile, const Topology& topo) {
  const Pattern& p = tile.pattern;
  Tiling T{p, tile.lattice, {}};
  for (size_t y = 0; y < topo.yarns.size(); ++y) {
    TileYarn t;
    Eigen::Vector2i c = Eigen::Vector2i::Zero();
    for (int v : topo.yarns[y]) {
      t.v.push_back(v);
      t.cell.push_back(c);
      c += topo.offset[v];
    }
    t.period = c;
    if (c[1] == 0 && std::abs(c[0]) == 1) t.dir = 0;
    else if (c[0] == 0 && std::abs(c[1]) == 1) t.dir = 1;
    else
      fail(p, "yarn " + std::to_string(y) + " advances by (" + std::to_string(c[0]) + ", " + std::to_string(c[1]) +
                  ") tiles per period; strips need yarns that run along x (course) or y (wale), one tile per period");
    const int across = 1 - t.dir;
    for (size_t i = 0; i < t.v.size(); ++i) {
      const Eigen::Vector2d o = T.A * t.cell[i].cast<double>();
      t.centre += (p.x[t.v[i]][across] + o[across]) / t.v.size();
    }
    T.yarns.push_back(std::move(t));
  }
  return T;
}

// Step 2: the rows whose centre line lies inside, per direction; for knits also the nearest
// outside course on each side (the bind-off rows of step 3).
struct RowChoice {
  std::vector<Row> rows[2];
  Row below, above;
};
RowChoice choose_rows(const Tiling& T, const Eigen::Vector2d& half) {
  RowChoice rc;
  rc.below.centre = -1e300;
  rc.above.centre = 1e300;
  for (size_t y = 0; y < T.yarns.size(); ++y) {
    const TileYarn& t = T.yarns[y];
    const int across = 1 - t.dir;
    // A copy shifted by one cell across moves the row by the lattice's diagonal entry.
    const double pa = across == 0 ? T.A(0, 0) : T.A(1, 1), lim = half[across];
    const long c_lo = static_cast<long>(std::ceil((-lim - t.centre) / pa - 1e-12));
    const long c_hi = static_cast<long>(std::floor((lim - t.centre) / pa + 1e-12));
    for (long c = c_lo; c <= c_hi; ++c) rc.rows[t.dir].push_back({int(y), int(c), t.centre + c * pa, false});
    if (t.centre + (c_hi + 1) * pa < rc.above.centre)
      rc.above = {int(y), int(c_hi + 1), t.centre + (c_hi + 1) * pa, true};
    if (t.centre + (c_lo - 1) * pa > rc.below.centre)
      rc.below = {int(y), int(c_lo - 1), t.centre + (c_lo - 1) * pa, true};
  }
  return rc;
}

// Kept range of a row: first to last vertex inside the strip's two ends.
void kept_range(const Tiling& T, const Eigen::Vector2d& half, Row& row) {
  const TileYarn& t = T.yarns[row.yarn];
  const long m = static_cast<long>(t.v.size());
  const double period = t.dir == 0 ? T.A(0, 0) : T.A(1, 1), lim = half[t.dir];
  const long Q = static_cast<long>(std::ceil(lim / period)) + 3;
  long first = 0, last = -1;
  bool any = false;
  for (long k = -Q * m; k < Q * m; ++k) {
    if (std::abs(T.position(row, k)[t.dir]) <= lim) {
      if (!any) first = k;
      last = k;
      any = true;
    }
  }
  if (!any || last - first + 1 < m)
    fail(T.p, "the strip is shorter than one period of its yarn rows (" + std::to_string(period) + " m)");
  row.k_first = first;
  row.k_last = last;
}

// Which tiling vertices inside the rectangle are not kept (dropped with their rows).
int dropped_vertices(const Tiling& T, const Eigen::Vector2d& half, const std::vector<Row> (&rows)[2]) {
  int dropped = 0;
  std::vector<Row> all;
  for (const auto& g : rows) all.insert(all.end(), g.begin(), g.end());
  for (size_t y = 0; y < T.yarns.size(); ++y) {
    const TileYarn& t = T.yarns[y];
    const int across = 1 - t.dir;
    const double pa = across == 0 ? T.A(0, 0) : T.A(1, 1), pl = t.dir == 0 ? T.A(0, 0) : T.A(1, 1);
    const long C = static_cast<long>(std::ceil(half[across] / pa)) + 3, m = static_cast<long>(t.v.size());
    const long Q = static_cast<long>(std::ceil(half[t.dir] / pl)) + 3;
    for (long c = -C; c <= C; ++c) {
      Row probe{int(y), int(c)};
      const Row* kept = nullptr;
      for (const Row& rr : all)
        if (rr.yarn == int(y) && rr.copy == int(c)) kept = &rr;
      for (long k = -Q * m; k < Q * m; ++k) {
        const Eigen::Vector3d x = T.position(probe, k);
        if (std::abs(x[0]) > half[0] || std::abs(x[1]) > half[1]) continue;
        if (!kept || k < kept->k_first || k > kept->k_last) ++dropped;
      }
    }
  }
  return dropped;
}

// Step 4: serpentine order and directions. Wefts (x rows) first, bottom to top, starting at
// -x; then the warps (y rows), starting at the corner where the wefts ended.
std::vector<Row> serpentine(std::vector<Row> (&rows)[2]) {
  std::vector<Row> order;
  for (size_t i = 0; i < rows[0].size(); ++i) {
    rows[0][i].sign = i % 2 == 0 ? 1 : -1;
    order.push_back(rows[0][i]);
  }
  if (!rows[1].empty()) {
    int first_sign = 1;
    if (!rows[0].empty()) {
      if (order.back().sign > 0) std::reverse(rows[1].begin(), rows[1].end());
      first_sign = -1;  // the corner is at the top: the first warp runs down
    }
    for (size_t i = 0; i < rows[1].size(); ++i) {
      rows[1][i].sign = i % 2 == 0 ? first_sign : -first_sign;
      order.push_back(rows[1][i]);
    }
  }
  return order;
}

// The rows' continuations beyond their ends, out to 2.5 radii beyond everything kept (the
// connectors' ports): exit_end[i] leaves row i at its end, exit_start[i] at its start.
struct Exits {
  std::vector<std::vector<PathVertex>> end, start;
};
Exits row_exits(const Tiling& T, const std::vector<Row>& order, double clearance) {
  // How far beyond everything kept a connector must leave before it turns: per axis and side.
  double outer[2][2];  // [axis][side: 0 for -, 1 for +]
  for (int a = 0; a < 2; ++a) outer[a][0] = outer[a][1] = -1e300;
  for (const Row& row : order)
    for (long k = row.k_first; k <= row.k_last; ++k) {
      const Eigen::Vector3d x = T.position(row, k);
      for (int a = 0; a < 2; ++a) {
        outer[a][0] = std::max(outer[a][0], -x[a]);
        outer[a][1] = std::max(outer[a][1], x[a]);
      }
    }
  // A row's continuation beyond one of its ends, from the end outwards (not including it).
  auto continuation = [&](int ri, bool at_end) {
    const Row& row = order[ri];
    const int dir = T.yarns[row.yarn].dir;
    // Traversal in k: +1 when traversing increases k.
    const int kstep = row.sign * T.k_sign(row);
    const long k0 = at_end ? (kstep > 0 ? row.k_last : row.k_first) : (kstep > 0 ? row.k_first : row.k_last);
    const int dk = at_end ? kstep : -kstep;
    const int side = at_end ? row.sign : -row.sign;  // +1: the + end of the axis
    const double bound = outer[dir][side > 0 ? 1 : 0] + clearance;
    std::vector<PathVertex> out;
    const long m = static_cast<long>(T.yarns[row.yarn].v.size());
    for (long k = k0 + dk;; k += dk) {
      if (std::abs(k - k0) > 4 * m) fail(T.p, "a row's continuation never leaves the strip");
      const StripSource src = T.source(row, k);
      const Eigen::Vector3d x = T.position(src);
      out.push_back({x, src, ri, k, true});
      if (side * x[dir] >= bound) break;
    }
    return out;
  };
  Exits ex;
  ex.end.resize(order.size());
  ex.start.resize(order.size());
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    ex.end[i] = continuation(int(i), true);
    ex.start[i + 1] = continuation(int(i) + 1, false);
  }
  return ex;
}

// The connectors between consecutive rows, routed in lanes (strip_route.hpp).
std::vector<Connector> connectors(const Tiling& T, const std::vector<Row>& order, const Exits& ex, double r,
                                  double gap) {
  std::vector<Connector> conns(order.empty() ? 0 : order.size() - 1);
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    Connector& c = conns[i];
    c.a = ex.end[i].back().x;
    c.b = ex.start[i + 1].back().x;
    c.da = T.yarns[order[i].yarn].dir;
    c.sa = order[i].sign;
    c.db = T.yarns[order[i + 1].yarn].dir;
    c.sb = -order[i + 1].sign;
  }
  double top = 0;
  for (const Row& row : order)
    for (long k = row.k_first; k <= row.k_last; ++k) top = std::max(top, std::abs(T.position(row, k)[2]));
  route_connectors(conns, top, r, gap);
  return conns;
}

// The one yarn: each row in its direction, then the connector to the next row (the
// continuation out of this row, the routed corners, the continuation into the next one,
// traversed inwards). h: the connectors' vertex spacing.
std::vector<PathVertex> assemble_path(const Tiling& T, const std::vector<Row>& order, const Exits& ex,
                                      const std::vector<Connector>& conns, double h, int& connectors) {
  std::vector<PathVertex> path;
  for (size_t i = 0; i < order.size(); ++i) {
    const Row& row = order[i];
    const int kstep = row.sign * T.k_sign(row);
    const long a = kstep > 0 ? row.k_first : row.k_last, b = kstep > 0 ? row.k_last : row.k_first;
    for (long k = a;; k += kstep) {
      const StripSource src = T.source(row, k);
      path.push_back({T.position(src), src, int(i), k, false});
      if (k == b) break;
    }
    if (i + 1 == order.size()) break;
    for (const PathVertex& v : ex.end[i]) path.push_back(v);
    const std::vector<Eigen::Vector3d>& corners = conns[i].corners;
    std::vector<Eigen::Vector3d> pts;
    for (size_t c = 0; c + 1 < corners.size(); ++c)
      if ((corners[c + 1] - corners[c]).norm() > 1e-9 * h) leg(corners[c], corners[c + 1], h, pts);
    pts.pop_back();  // B's port is the continuation's last vertex, added below
    for (const Eigen::Vector3d& q : pts) path.push_back({q, StripSource{}, -1, 0, false});
    for (auto it = ex.start[i + 1].rbegin(); it != ex.start[i + 1].rend(); ++it) path.push_back(*it);
    ++connectors;
  }
  return path;
}

// Step 5, the rest state from the pattern where the path follows it.
class RestFromPattern {
 public:
  RestFromPattern(const Pattern& p, const std::vector<Row>& order, const std::vector<PathVertex>& path, Strip& s)
      : p_(p), order_(order), path_(path), s_(s) {}

  // Edges: an edge between consecutive vertices of the same row is an edge of the tiling and
  // takes the pattern's frame; a forward edge k -> k+1 is the pattern's edge of vertex k, a
  // backward one k -> k-1 the pattern's edge of vertex k-1 reversed (theta -> -theta keeps
  // its material frame: d2 = t x d1 flips with t). It is yarn (not boundary yarn) when both
  // ends are kept vertices of a row that is not a bind-off row.
  void edges() {
    const int ne = static_cast<int>(path_.size()) - 1;  // an open yarn
    s_.theta.assign(ne, 0.0);
    s_.rest_length.assign(ne, 0.0);
    s_.ref_d1.assign(ne, Eigen::Vector3d::Zero());
    s_.connector_edge.assign(ne, 1);
    tan_.resize(ne);
    for (int e = 0; e < ne; ++e) {
      tan_[e] = (s_.x[e + 1] - s_.x[e]).normalized();
      if (tiling_edge(e)) {
        const bool fwd = path_[e + 1].k > path_[e].k;
        const int pv = fwd ? path_[e].src.vertex : path_[e + 1].src.vertex;  // the pattern edge's start
        const Eigen::Vector3d d = p_.ref_d1[pv] - p_.ref_d1[pv].dot(tan_[e]) * tan_[e];
        s_.ref_d1[e] = d.normalized();
        s_.theta[e] = fwd ? p_.theta[pv] : -p_.theta[pv];
        s_.rest_length[e] = p_.rest_length[pv];
      } else {
        const Eigen::Vector3d d =
            e == 0 ? any_perpendicular(tan_[e]) : transported_director({tan_[e - 1], s_.ref_d1[e - 1]}, tan_[e]);
        s_.ref_d1[e] = d;
      }
      if (yarn_edge(e)) s_.connector_edge[e] = 0;
    }
  }

  // Joints: yarn joints (both edges yarn) take the pattern's rest curvature and twist at their
  // vertex (k2 -> -k2 when traversed backwards); boundary joints are stress-free now.
  void joints() {
    const int n = static_cast<int>(path_.size());
    s_.rest_kappa.assign(n, Eigen::Vector2d::Zero());
    s_.rest_twist.assign(n, 0.0);
    s_.ref_twist.assign(n, 0.0);
    s_.connector_joint.assign(n, 1);
    for (int v = 1; v + 1 < n; ++v) {
      const int a = v - 1;
      const bool yarn = yarn_edge(a) && yarn_edge(v);
      const double hint = yarn ? p_.ref_twist[path_[v].src.vertex] : 0.0;
      s_.ref_twist[v] = reference_twist(tan_[a], s_.ref_d1[a], tan_[v], s_.ref_d1[v], hint);
      if (yarn) {
        const int pv = path_[v].src.vertex;
        const bool fwd = path_[v + 1].k > path_[v].k;
        s_.rest_kappa[v] = Eigen::Vector2d(p_.rest_kappa[pv][0], fwd ? p_.rest_kappa[pv][1] : -p_.rest_kappa[pv][1]);
        s_.rest_twist[v] = p_.rest_twist[pv];
        s_.connector_joint[v] = 0;
      }
    }
  }

 private:
  bool tiling_edge(int e) const {
    return path_[e].row >= 0 && path_[e].row == path_[e + 1].row && std::abs(path_[e + 1].k - path_[e].k) == 1;
  }
  bool yarn_edge(int e) const {
    return tiling_edge(e) && !path_[e].exit && !path_[e + 1].exit && !order_[path_[e].row].soft;
  }

  const Pattern& p_;
  const std::vector<Row>& order_;
  const std::vector<PathVertex>& path_;
  Strip& s_;
  std::vector<Eigen::Vector3d> tan_;
};

// The strip's name, sizes and tile counts from the spec.
Strip strip_header(const StripSpec& spec, const Tiling& T) {
  Strip s;
  s.name = T.p.name + "_" + to_string(spec.axis);
  s.radius = T.p.radius;
  s.width = spec.width;
  s.length = spec.length;
  s.axis = spec.axis;
  s.connector_scale = spec.connector_scale;
  s.tiles_x = static_cast<int>(std::ceil(s.extent_x() / T.A(0, 0) - 1e-9));
  s.tiles_y = static_cast<int>(std::ceil(s.extent_y() / T.A(1, 1) - 1e-9));
  return s;
}

// The width that carries the load: the rows along the long axis times their across period,
// per row of the tile.
double load_width(const Strip& s, const StripSpec& spec, const Tiling& T, const std::vector<Row> (&rows)[2]) {
  const int dl = spec.axis == StripAxis::kCourse ? 0 : 1;  // rows along the long axis
  const int per_tile = static_cast<int>(
      std::count_if(T.yarns.begin(), T.yarns.end(), [&](const TileYarn& t) { return t.dir == dl; }));
  const double pa = dl == 0 ? T.A(1, 1) : T.A(0, 0);  // their across period
  return !rows[dl].empty() && per_tile > 0 ? double(rows[dl].size()) * pa / per_tile : s.width;
}

}  // namespace

Strip generate_strip(const StripTile& tile, const StripSpec& spec) {
  const Pattern& p = tile.pattern;
  if (!(spec.width > 0 && spec.length > 0)) fail(p, "width and length must be positive");
  if (!(spec.connector_scale > 0)) fail(p, "connector scale must be positive");
  if (static_cast<int>(p.rest_length.size()) != p.size()) fail(p, "the pattern has no rest state");
  const Topology topo = topology(p);
  if (tile.lattice(1, 0) != 0.0 || !(tile.lattice(0, 0) > 0 && tile.lattice(1, 1) > 0))
    fail(p, "the lattice must be upper triangular with a positive diagonal (first vector along x)");
  const Tiling T = make_tiling(tile, topo);
  const double r = p.radius;
  double h = 0;  // connector vertex spacing: the pattern's mean rest length
  for (double L : p.rest_length) h += L / p.size();

  Strip s = strip_header(spec, T);
  const Eigen::Vector2d half(0.5 * s.extent_x(), 0.5 * s.extent_y());
  const bool knit = std::all_of(T.yarns.begin(), T.yarns.end(), [](const TileYarn& t) { return t.dir == 0; });
  RowChoice rc = choose_rows(T, half);
  std::vector<Row>(&rows)[2] = rc.rows;
  if (rows[0].empty() && rows[1].empty()) fail(p, "no yarn row lies inside the strip (is it narrower than a tile?)");
  s.rows = static_cast<int>(rows[0].size() + rows[1].size());
  s.load_width = load_width(s, spec, T, rows);
  if (knit && spec.bind_off) {
    rows[0].push_back(rc.below);
    rows[0].push_back(rc.above);
    s.boundary_rows = 2;
  }
  for (int d = 0; d < 2; ++d)
    std::stable_sort(rows[d].begin(), rows[d].end(), [](const Row& a, const Row& b) { return a.centre < b.centre; });
  for (auto& g : rows)
    for (Row& row : g) kept_range(T, half, row);
  s.dropped_vertices += dropped_vertices(T, half, rows);
  const std::vector<Row> order = serpentine(rows);
  const double clearance = 2.5 * r;
  const Exits ex = row_exits(T, order, clearance);
  const std::vector<Connector> conns = connectors(T, order, ex, r, clearance);  // gap 1.25 x 2r
  const std::vector<PathVertex> path = assemble_path(T, order, ex, conns, h, s.connectors);

  // Geometry and provenance, then the rest state.
  const int n = static_cast<int>(path.size());
  s.x.resize(n);
  s.source.resize(n);
  for (int i = 0; i < n; ++i) {
    s.x[i] = path[i].x;
    s.source[i] = path[i].src;
  }
  RestFromPattern rest(p, order, path, s);
  rest.edges();
  rest.joints();
  set_rest_to_shape(s);
  check_strip(s);
  return s;
}

}  // namespace yarnhom::yarn
