#pragma once
// Does a term's node grid lie on one branch of equilibria? (issue 12: the data smoothness that
// every fit inherits.)
//
// The yarn RVE can have several local minima at one strain (a buckled tile folds one way or the
// other; a loop slides past its neighbour or not). Warm starts follow whichever branch their
// path reached, so two neighbouring nodes solved along different paths (different sectors of
// Algorithm 1, or a 2D grid row against its own axis node) may sit on different branches. The
// data then disagree with themselves: their energies jump between the nodes while the gradients
// (exact, from the envelope theorem) say they should not. No smooth network can fit that.
//
// The check is the trapezoid rule along each grid edge: for neighbours n, m along axis d,
//   mismatch = (Psi_m - Psi_n) - (g_n + g_m)/2 * (t_m - t_n),
// which for a smooth energy is O(h^3 Psi'''), and for two branches is their energy gap. It is
// reported relative to the term's typical edge change along that axis, mean |(g_n + g_m)/2 dt|.
#include <Eigen/Core>
#include <vector>

namespace yarnhom::yarn {

struct GridEdge {
  int a = 0, b = 0;       // node indices in the term's node order (term_nodes: row-major)
  int axis = 0;           // the term axis the edge runs along
  double relative = 0;    // |mismatch| / typical |edge change| along that axis
};

// Every edge between two usable nodes of a term's grid (1D: m nodes; 2D: m x m, row-major, as
// term_nodes lays them out). t: node coordinates; psi: energies; g: gradients along the term
// axes; ok: whether a node is usable. Throws std::invalid_argument on inconsistent sizes.
std::vector<GridEdge> grid_edges(int dim, int m, const std::vector<Eigen::VectorXd>& t, const std::vector<double>& psi,
                                 const std::vector<Eigen::VectorXd>& g, const std::vector<bool>& ok);

// The edges whose relative mismatch exceeds `tolerance` (the data disagree with themselves).
std::vector<GridEdge> inconsistent_edges(const std::vector<GridEdge>& edges, double tolerance);

// Typical |edge change| along each axis (the denominators of `relative`), for an energy
// tolerance in the same units.
std::vector<double> edge_scales(int dim, int m, const std::vector<Eigen::VectorXd>& t,
                                const std::vector<Eigen::VectorXd>& g, const std::vector<bool>& ok);

}  // namespace yarnhom::yarn
