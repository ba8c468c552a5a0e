#pragma once
// Connector routing in lanes, for generate_strip (strip_generate.cpp; docs/strip.md section 1).
//
// A connector leaves its port A straight out along the row's axis, at the port's own across
// coordinate and height, to its lane: a plane normal to that axis beyond every port of its
// side; in that plane it runs to the other port's across coordinate and height (straight, or
// over the top or under the bottom of everything), and goes straight back in to port B. Two
// connectors' legs along the axis are as far apart as their ports (points of different rows of
// the tiling), and what can come near a connector's run inside its lane is another
// connector's leg passing through that plane on its way to a lane further out: so lanes are
// filled greedily from the inside, each connector in the innermost lane where one of its runs
// keeps clear of every port whose leg passes through the lane and of the runs already there.
// (The first design, one shared column at alternating heights 3r above and below the
// mid-plane with vertical risers at the ports, left slip-stitch strips with risers 0.20 x 2r
// apart: their ports lie up to 4.3r out of the mid-plane, and the risers crossed each other's
// heights.)
#include <Eigen/Core>
#include <vector>

namespace yarnhom::yarn {

struct Connector {
  Eigen::Vector3d a, b;                // ports
  int da = 0, sa = 1, db = 0, sb = 1;  // axis and side of each port
  int lane = 0;
  std::vector<Eigen::Vector2d> run;  // (across, z) polyline in the lane, from a to b
  std::vector<Eigen::Vector3d> corners;
};

// Routes every connector (its lane, run and corners, from port a to port b). top: the largest
// |z| of the kept vertices; r: the yarn radius; gap: the clearance between lanes and beyond
// the ports (1.25 x 2r: beyond the contact kernel's reach).
void route_connectors(std::vector<Connector>& conns, double top, double r, double gap);

}  // namespace yarnhom::yarn
