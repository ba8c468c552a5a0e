#include "yarn/strip_generate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "yarn/frames.hpp"
#include "yarn/rod.hpp"
#include "yarn/segment_distance.hpp"

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

Strip generate_strip(const StripTile& tile, const StripSpec& spec) {
  const Pattern& p = tile.pattern;
  auto fail = [&](const std::string& what) {
    throw std::invalid_argument("strip of pattern '" + p.name + "': " + what);
  };
  if (!(spec.width > 0 && spec.length > 0)) fail("width and length must be positive");
  if (!(spec.connector_scale > 0)) fail("connector scale must be positive");
  if (static_cast<int>(p.rest_length.size()) != p.size()) fail("the pattern has no rest state");
  const Topology topo = topology(p);
  if (tile.lattice(1, 0) != 0.0 || !(tile.lattice(0, 0) > 0 && tile.lattice(1, 1) > 0))
    fail("the lattice must be upper triangular with a positive diagonal (first vector along x)");
  Tiling T{p, tile.lattice, {}};
  const double r = p.radius;
  double h = 0;  // connector vertex spacing: the pattern's mean rest length
  for (double L : p.rest_length) h += L / p.size();

  // Tile yarns, unrolled.
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
      fail("yarn " + std::to_string(y) + " advances by (" + std::to_string(c[0]) + ", " + std::to_string(c[1]) +
           ") tiles per period; strips need yarns that run along x (course) or y (wale), one tile per period");
    const int across = 1 - t.dir;
    for (size_t i = 0; i < t.v.size(); ++i) {
      const Eigen::Vector2d o = T.A * t.cell[i].cast<double>();
      t.centre += (p.x[t.v[i]][across] + o[across]) / t.v.size();
    }
    T.yarns.push_back(std::move(t));
  }

  Strip s;
  s.name = p.name + "_" + to_string(spec.axis);
  s.radius = r;
  s.width = spec.width;
  s.length = spec.length;
  s.axis = spec.axis;
  s.connector_scale = spec.connector_scale;
  const Eigen::Vector2d half(0.5 * s.extent_x(), 0.5 * s.extent_y());
  s.tiles_x = static_cast<int>(std::ceil(s.extent_x() / T.A(0, 0) - 1e-9));
  s.tiles_y = static_cast<int>(std::ceil(s.extent_y() / T.A(1, 1) - 1e-9));
  const bool knit = std::all_of(T.yarns.begin(), T.yarns.end(), [](const TileYarn& t) { return t.dir == 0; });

  // Rows whose centre line lies inside; for knits also the nearest outside course on each
  // side (the bind-off rows).
  std::vector<Row> rows[2];
  Row below, above;
  below.centre = -1e300;
  above.centre = 1e300;
  for (size_t y = 0; y < T.yarns.size(); ++y) {
    const TileYarn& t = T.yarns[y];
    const int across = 1 - t.dir;
    // A copy shifted by one cell across moves the row by the lattice's diagonal entry.
    const double pa = across == 0 ? T.A(0, 0) : T.A(1, 1), lim = half[across];
    const long c_lo = static_cast<long>(std::ceil((-lim - t.centre) / pa - 1e-12));
    const long c_hi = static_cast<long>(std::floor((lim - t.centre) / pa + 1e-12));
    for (long c = c_lo; c <= c_hi; ++c) rows[t.dir].push_back({int(y), int(c), t.centre + c * pa, false});
    if (t.centre + (c_hi + 1) * pa < above.centre) above = {int(y), int(c_hi + 1), t.centre + (c_hi + 1) * pa, true};
    if (t.centre + (c_lo - 1) * pa > below.centre) below = {int(y), int(c_lo - 1), t.centre + (c_lo - 1) * pa, true};
  }
  if (rows[0].empty() && rows[1].empty()) fail("no yarn row lies inside the strip (is it narrower than a tile?)");
  s.rows = static_cast<int>(rows[0].size() + rows[1].size());
  {
    const int dl = spec.axis == StripAxis::kCourse ? 0 : 1;  // rows along the long axis
    const int per_tile = static_cast<int>(
        std::count_if(T.yarns.begin(), T.yarns.end(), [&](const TileYarn& t) { return t.dir == dl; }));
    const double pa = dl == 0 ? T.A(1, 1) : T.A(0, 0);  // their across period
    s.load_width = !rows[dl].empty() && per_tile > 0 ? double(rows[dl].size()) * pa / per_tile : s.width;
  }
  if (knit && spec.bind_off) {
    rows[0].push_back(below);
    rows[0].push_back(above);
    s.boundary_rows = 2;
  }
  for (int d = 0; d < 2; ++d)
    std::stable_sort(rows[d].begin(), rows[d].end(), [](const Row& a, const Row& b) { return a.centre < b.centre; });

  // Kept range of each row: first to last vertex inside the strip's two ends.
  auto kept_range = [&](Row& row) {
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
      fail("the strip is shorter than one period of its yarn rows (" + std::to_string(period) + " m)");
    row.k_first = first;
    row.k_last = last;
  };
  for (auto& g : rows)
    for (Row& row : g) kept_range(row);

  // Which tiling vertices inside the rectangle are not kept (dropped with their rows).
  {
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
          if (!kept || k < kept->k_first || k > kept->k_last) ++s.dropped_vertices;
        }
      }
    }
  }

  // Serpentine order and directions. Wefts (x rows) first, bottom to top, starting at -x;
  // then the warps (y rows), starting at the corner where the wefts ended.
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
  const double clearance = 2.5 * r;

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
      if (std::abs(k - k0) > 4 * m) fail("a row's continuation never leaves the strip");
      const StripSource src = T.source(row, k);
      const Eigen::Vector3d x = T.position(src);
      out.push_back({x, src, ri, k, true});
      if (side * x[dir] >= bound) break;
    }
    return out;
  };

  std::vector<std::vector<PathVertex>> exit_end(order.size()), exit_start(order.size());
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    exit_end[i] = continuation(int(i), true);
    exit_start[i + 1] = continuation(int(i) + 1, false);
  }
  // Connector routing in lanes. A connector leaves its port A straight out along the row's
  // axis, at the port's own across coordinate and height, to its lane: a plane normal to that
  // axis beyond every port of its side; in that plane it runs to the other port's across
  // coordinate and height (straight, or over the top or under the bottom of everything), and
  // goes straight back in to port B. Two connectors' legs along the axis are as far apart as
  // their ports (points of different rows of the tiling), and what can come near a
  // connector's run inside its lane is another connector's leg passing through that plane on
  // its way to a lane further out: so lanes are filled greedily from the inside, each
  // connector in the innermost lane where one of its runs keeps clear of every port whose
  // leg passes through the lane and of the runs already there. (The first design, one
  // shared column at alternating heights 3r above and below the mid-plane with vertical
  // risers at the ports, left slip-stitch strips with risers 0.20 x 2r apart: their ports lie
  // up to 4.3r out of the mid-plane, and the risers crossed each other's heights.)
  const double gap = clearance;  // 1.25 x 2r: beyond the contact kernel's reach
  struct Connector {
    Eigen::Vector3d a, b;                // ports
    int da = 0, sa = 1, db = 0, sb = 1;  // axis and side of each port
    int lane = 0;
    std::vector<Eigen::Vector2d> run;  // (across, z) polyline in the lane, from a to b
    std::vector<Eigen::Vector3d> corners;
  };
  std::vector<Connector> conns(order.empty() ? 0 : order.size() - 1);
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    Connector& c = conns[i];
    c.a = exit_end[i].back().x;
    c.b = exit_start[i + 1].back().x;
    c.da = T.yarns[order[i].yarn].dir;
    c.sa = order[i].sign;
    c.db = T.yarns[order[i + 1].yarn].dir;
    c.sb = -order[i + 1].sign;
  }
  auto side_index = [](int side) { return side > 0 ? 1 : 0; };
  // Per (axis, side): the first lane (beyond the farthest port); one height beyond everything
  // kept and every port, for runs over the top or under the bottom.
  double first_lane[2][2], top = 0;
  for (int a = 0; a < 2; ++a) first_lane[a][0] = first_lane[a][1] = -1e300;
  for (const Connector& c : conns) {
    double& fa = first_lane[c.da][side_index(c.sa)];
    double& fb = first_lane[c.db][side_index(c.sb)];
    fa = std::max(fa, c.sa * c.a[c.da] + gap);
    fb = std::max(fb, c.sb * c.b[c.db] + gap);
    top = std::max({top, std::abs(c.a[2]), std::abs(c.b[2])});
  }
  for (const Row& row : order)
    for (long k = row.k_first; k <= row.k_last; ++k) top = std::max(top, std::abs(T.position(row, k)[2]));
  const double height = top + gap;
  // Distances in a lane's plane, (across, z).
  auto in_plane = [](const Eigen::Vector2d& p) { return Eigen::Vector3d(p[0], p[1], 0); };
  auto seg2 = [&](const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, const Eigen::Vector2d& q0, const Eigen::Vector2d& q1) {
    return segment_distance(in_plane(p0), in_plane(p1), in_plane(q0), in_plane(q1));
  };
  auto across_z = [](const Eigen::Vector3d& x, int dir) { return Eigen::Vector2d(x[1 - dir], x[2]); };
  int lanes_used[2][2] = {{0, 0}, {0, 0}};
  for (int a = 0; a < 2; ++a)
    for (int sd : {-1, 1}) {
      std::vector<int> left;  // connectors with both ports on this side, not yet in a lane
      for (size_t i = 0; i < conns.size(); ++i)
        if (conns[i].da == a && conns[i].db == a && conns[i].sa == sd) left.push_back(int(i));
      // The corner connector's legs pass through every lane of its sides (it is outermost).
      std::vector<Eigen::Vector2d> fixed;
      for (const Connector& c : conns)
        if (c.da != c.db) {
          if (c.da == a && c.sa == sd) fixed.push_back(across_z(c.a, a));
          if (c.db == a && c.sb == sd) fixed.push_back(across_z(c.b, a));
        }
      // How far a run must stay from the legs passing through its lane and from the other
      // runs there: beyond the contact kernel's reach (2r), or, where two ports of this side
      // are closer than that (rows in contact), as far as those ports are from each other
      // (their legs along the axis are that close anyway).
      std::vector<Eigen::Vector2d> ports = fixed;
      for (int ci : left) {
        ports.push_back(across_z(conns[ci].a, a));
        ports.push_back(across_z(conns[ci].b, a));
      }
      double need = 2 * r;
      for (size_t i = 0; i < ports.size(); ++i)
        for (size_t j = 0; j < i; ++j) need = std::min(need, 0.99 * (ports[i] - ports[j]).norm());
      for (int lane = 0; !left.empty(); ++lane) {
        std::vector<int> placed;
        for (int ci : left) {
          Connector& c = conns[ci];
          std::vector<Eigen::Vector2d> obstacles = fixed;
          for (int o : left)
            if (o != ci && std::find(placed.begin(), placed.end(), o) == placed.end()) {
              obstacles.push_back(across_z(conns[o].a, a));
              obstacles.push_back(across_z(conns[o].b, a));
            }
          const Eigen::Vector2d pa = across_z(c.a, a), pb = across_z(c.b, a);
          const std::vector<Eigen::Vector2d> options[3] = {
              {pa, pb}, {pa, {pa[0], height}, {pb[0], height}, pb}, {pa, {pa[0], -height}, {pb[0], -height}, pb}};
          auto clearance_of = [&](const std::vector<Eigen::Vector2d>& run) {
            double d = std::numeric_limits<double>::infinity();
            for (size_t k = 0; k + 1 < run.size(); ++k) {
              for (const Eigen::Vector2d& q : obstacles) d = std::min(d, seg2(q, q, run[k], run[k + 1]));
              for (int o : placed)
                for (size_t m = 0; m + 1 < conns[o].run.size(); ++m)
                  d = std::min(d, seg2(run[k], run[k + 1], conns[o].run[m], conns[o].run[m + 1]));
            }
            return d;
          };
          int chosen = -1, best = 0;
          double best_d = -1;
          for (int k = 0; k < 3 && chosen < 0; ++k) {
            const double d = clearance_of(options[k]);
            if (d >= need) chosen = k;
            if (d > best_d) best_d = d, best = k;
          }
          // Nothing fits: the first connector of a lane takes its best run anyway (the strip's
          // certificate then says whether it is good enough); the others wait for a lane.
          if (chosen < 0 && !placed.empty()) continue;
          c.run = options[chosen < 0 ? best : chosen];
          c.lane = lane;
          placed.push_back(ci);
        }
        lanes_used[a][side_index(sd)] = lane + 1;
        std::vector<int> rest;
        for (int ci : left)
          if (std::find(placed.begin(), placed.end(), ci) == placed.end()) rest.push_back(ci);
        left = std::move(rest);
      }
    }
  auto lane_position = [&](int a, int sd, int lane) { return sd * (first_lane[a][side_index(sd)] + lane * gap); };
  for (Connector& c : conns) {
    std::vector<Eigen::Vector3d>& q = c.corners;
    q.push_back(c.a);
    if (c.da == c.db) {
      const double at = lane_position(c.da, c.sa, c.lane);
      for (const Eigen::Vector2d& p : c.run) {
        Eigen::Vector3d x(0, 0, p[1]);
        x[c.da] = at;
        x[1 - c.da] = p[0];
        q.push_back(x);
      }
    } else {
      // The corner connector (wovens: the last weft to the first warp), in lanes beyond every
      // other lane of both its sides, over the top of everything.
      Eigen::Vector3d x = c.a;
      x[c.da] = lane_position(c.da, c.sa, lanes_used[c.da][side_index(c.sa)]);
      q.push_back(x);
      x[2] = height;
      q.push_back(x);
      x[c.db] = lane_position(c.db, c.sb, lanes_used[c.db][side_index(c.sb)]);
      q.push_back(x);
      x[c.da] = c.b[c.da];
      q.push_back(x);
      x[2] = c.b[2];
      q.push_back(x);
    }
    q.push_back(c.b);
  }

  // Assemble the path.
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
    // Connector to the next row: the continuation out of this row, the routed corners, the
    // continuation into the next one (traversed inwards).
    for (const PathVertex& v : exit_end[i]) path.push_back(v);
    const std::vector<Eigen::Vector3d>& corners = conns[i].corners;
    std::vector<Eigen::Vector3d> pts;
    for (size_t c = 0; c + 1 < corners.size(); ++c)
      if ((corners[c + 1] - corners[c]).norm() > 1e-9 * h) leg(corners[c], corners[c + 1], h, pts);
    pts.pop_back();  // B's port is the continuation's last vertex, added below
    for (const Eigen::Vector3d& q : pts) path.push_back({q, StripSource{}, -1, 0, false});
    for (auto it = exit_start[i + 1].rbegin(); it != exit_start[i + 1].rend(); ++it) path.push_back(*it);
    ++s.connectors;
  }

  // Geometry and provenance.
  const int n = static_cast<int>(path.size());
  s.x.resize(n);
  s.source.resize(n);
  for (int i = 0; i < n; ++i) {
    s.x[i] = path[i].x;
    s.source[i] = path[i].src;
  }
  const int ne = n - 1;  // an open yarn

  // Edges: an edge between consecutive vertices of the same row is an edge of the tiling and
  // takes the pattern's frame; a forward edge k -> k+1 is the pattern's edge of vertex k, a
  // backward one k -> k-1 the pattern's edge of vertex k-1 reversed (theta -> -theta keeps
  // its material frame: d2 = t x d1 flips with t). It is yarn (not boundary yarn) when both
  // ends are kept vertices of a row that is not a bind-off row.
  auto tiling_edge = [&](int e) { return path[e].row >= 0 && path[e].row == path[e + 1].row && std::abs(path[e + 1].k - path[e].k) == 1; };
  auto yarn_edge = [&](int e) { return tiling_edge(e) && !path[e].exit && !path[e + 1].exit && !order[path[e].row].soft; };
  s.theta.assign(ne, 0.0);
  s.rest_length.assign(ne, 0.0);
  s.ref_d1.assign(ne, Eigen::Vector3d::Zero());
  s.connector_edge.assign(ne, 1);
  std::vector<Eigen::Vector3d> tan(ne);
  for (int e = 0; e < ne; ++e) {
    tan[e] = (s.x[e + 1] - s.x[e]).normalized();
    if (tiling_edge(e)) {
      const bool fwd = path[e + 1].k > path[e].k;
      const int pv = fwd ? path[e].src.vertex : path[e + 1].src.vertex;  // the pattern edge's start
      const Eigen::Vector3d d = p.ref_d1[pv] - p.ref_d1[pv].dot(tan[e]) * tan[e];
      s.ref_d1[e] = d.normalized();
      s.theta[e] = fwd ? p.theta[pv] : -p.theta[pv];
      s.rest_length[e] = p.rest_length[pv];
    } else {
      const Eigen::Vector3d d =
          e == 0 ? any_perpendicular(tan[e]) : transported_director({tan[e - 1], s.ref_d1[e - 1]}, tan[e]);
      s.ref_d1[e] = d;
    }
    if (yarn_edge(e)) s.connector_edge[e] = 0;
  }

  // Joints: yarn joints (both edges yarn) take the pattern's rest curvature and twist at their
  // vertex (k2 -> -k2 when traversed backwards); boundary joints are stress-free now.
  s.rest_kappa.assign(n, Eigen::Vector2d::Zero());
  s.rest_twist.assign(n, 0.0);
  s.ref_twist.assign(n, 0.0);
  s.connector_joint.assign(n, 1);
  for (int v = 1; v + 1 < n; ++v) {
    const int a = v - 1;
    const bool yarn = yarn_edge(a) && yarn_edge(v);
    const double hint = yarn ? p.ref_twist[path[v].src.vertex] : 0.0;
    s.ref_twist[v] = reference_twist(tan[a], s.ref_d1[a], tan[v], s.ref_d1[v], hint);
    if (yarn) {
      const int pv = path[v].src.vertex;
      const bool fwd = path[v + 1].k > path[v].k;
      s.rest_kappa[v] = Eigen::Vector2d(p.rest_kappa[pv][0], fwd ? p.rest_kappa[pv][1] : -p.rest_kappa[pv][1]);
      s.rest_twist[v] = p.rest_twist[pv];
      s.connector_joint[v] = 0;
    }
  }
  set_rest_to_shape(s);
  check_strip(s);
  return s;
}

}  // namespace yarnhom::yarn
