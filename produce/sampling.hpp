#pragma once
// Where the producer samples Psi, and in which order (supplement Algorithm 1).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/terms.hpp"

namespace yarnhom::yarn {

// n points on [lower, upper] (lower < 0 < upper) that include both ends and 0, evenly spaced on
// each side of 0 (spec section 3: grids contain 0 on every axis).
std::vector<double> axis_points(double lower, double upper, int n);

// The node points of one term: 1D, n points; 2D, the n x n tensor grid (row-major over the
// term's first index). Coordinates in the term's own order (term.indices).
std::vector<Eigen::VectorXd> term_nodes(const Term& t, const std::vector<Range>& box, int n);

// Algorithm 1 within one sector. `nodes` are in normalized units (each axis divided by the
// box's larger half-width, so the origin stays at 0 and the box fits in [-1, 1]^d). parent[i]:
// the nearest node of strictly smaller norm (ties: the lower index), -1 for a node at the
// origin or one with no smaller node in its sector (it starts from the rest state, the
// origin's solution). order: breadth-first from the origin, children in index order.
struct WarmStartPlan {
  std::vector<int> parent;
  std::vector<int> order;
};
WarmStartPlan algorithm1(const std::vector<Eigen::VectorXd>& nodes);

// The sector of a normalized node: 1D, 0 for t < 0 and 1 for t > 0; 2D, K sectors by polar
// angle, sector k covering [-pi + 2 pi k / K, -pi + 2 pi (k+1) / K). The origin: -1 (it is
// the rest state, shared by every sector).
int sector_of(const Eigen::VectorXd& normalized, int sectors);

}  // namespace yarnhom::yarn
