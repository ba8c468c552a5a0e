#include "yarn/strip/strip_route.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "numerics/segment_distance.hpp"

namespace yarnhom::yarn {

using numerics::segment_distance;

namespace {

int side_index(int side) { return side > 0 ? 1 : 0; }

// Distances in a lane's plane, (across, z).
double seg2(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, const Eigen::Vector2d& q0, const Eigen::Vector2d& q1) {
  auto in_plane = [](const Eigen::Vector2d& p) { return Eigen::Vector3d(p[0], p[1], 0); };
  return segment_distance(in_plane(p0), in_plane(p1), in_plane(q0), in_plane(q1));
}

Eigen::Vector2d across_z(const Eigen::Vector3d& x, int dir) { return Eigen::Vector2d(x[1 - dir], x[2]); }

struct Lanes {
  // Per (axis, side): the first lane (beyond the farthest port) and the lanes used; one height
  // beyond everything kept and every port, for runs over the top or under the bottom.
  double first[2][2];
  int used[2][2] = {{0, 0}, {0, 0}};
  double height = 0;
  double gap = 0;
  double position(int a, int sd, int lane) const { return sd * (first[a][side_index(sd)] + lane * gap); }
};

Lanes lane_bounds(const std::vector<Connector>& conns, double top, double gap) {
  Lanes L;
  L.gap = gap;
  for (int a = 0; a < 2; ++a) L.first[a][0] = L.first[a][1] = -1e300;
  for (const Connector& c : conns) {
    double& fa = L.first[c.da][side_index(c.sa)];
    double& fb = L.first[c.db][side_index(c.sb)];
    fa = std::max(fa, c.sa * c.a[c.da] + gap);
    fb = std::max(fb, c.sb * c.b[c.db] + gap);
    top = std::max({top, std::abs(c.a[2]), std::abs(c.b[2])});
  }
  L.height = top + gap;
  return L;
}

// The connectors with both ports on side sd of axis a, lane by lane from the inside.
void fill_lanes(std::vector<Connector>& conns, int a, int sd, double r, Lanes& L) {
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
  // How far a run must stay from the legs passing through its lane and from the other runs
  // there: beyond the contact kernel's reach (2r), or, where two ports of this side are closer
  // than that (rows in contact), as far as those ports are from each other (their legs along
  // the axis are that close anyway).
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
      const double height = L.height;
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
    L.used[a][side_index(sd)] = lane + 1;
    std::vector<int> rest;
    for (int ci : left)
      if (std::find(placed.begin(), placed.end(), ci) == placed.end()) rest.push_back(ci);
    left = std::move(rest);
  }
}

// The corners of a routed connector, from port a to port b.
void corners(Connector& c, const Lanes& L) {
  std::vector<Eigen::Vector3d>& q = c.corners;
  q.push_back(c.a);
  if (c.da == c.db) {
    const double at = L.position(c.da, c.sa, c.lane);
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
    x[c.da] = L.position(c.da, c.sa, L.used[c.da][side_index(c.sa)]);
    q.push_back(x);
    x[2] = L.height;
    q.push_back(x);
    x[c.db] = L.position(c.db, c.sb, L.used[c.db][side_index(c.sb)]);
    q.push_back(x);
    x[c.da] = c.b[c.da];
    q.push_back(x);
    x[2] = c.b[2];
    q.push_back(x);
  }
  q.push_back(c.b);
}

}  // namespace

void route_connectors(std::vector<Connector>& conns, double top, double r, double gap) {
  Lanes L = lane_bounds(conns, top, gap);
  for (int a = 0; a < 2; ++a)
    for (int sd : {-1, 1}) fill_lanes(conns, a, sd, r, L);
  for (Connector& c : conns) corners(c, L);
}

}  // namespace yarnhom::yarn
