#pragma once
// Prescribed vertices: pins (fixed where they start) and handles that translate along a
// piecewise-linear path of keyframes (t, dx, dy, dz), offsets from their starting positions.
// t is time in seconds for dynamic runs and the load parameter in [0, 1] for quasi-static
// runs. Before the first keyframe the offset is the first keyframe's, after the last the
// last's.
#include <Eigen/Core>
#include <array>
#include <vector>

namespace yarnhom::sim {

struct Handle {
  std::vector<int> vertices;
  std::vector<std::array<double, 4>> path;  // (t, dx, dy, dz), t increasing; empty = pinned
};

Eigen::Vector3d handle_offset(const Handle& h, double t);

// Every prescribed vertex (pins and handles), sorted, without repeats.
std::vector<int> prescribed_vertices(const std::vector<Handle>& handles);

// x0: 3n starting positions. Returns 3n with the prescribed vertices at their targets for t
// (other entries copied from x0).
Eigen::VectorXd handle_targets(const std::vector<Handle>& handles, const Eigen::VectorXd& x0, double t);

}  // namespace yarnhom::sim
