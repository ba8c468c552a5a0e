#pragma once
// A periodic yarn pattern: one tile (px x py) of closed yarns, in HYLC's `.pyp` format
// (spec section 4). Reading refuses a malformed file naming the file, the line and the
// problem; writing is exact (17 significant digits) and atomic.
//
// Index conventions, checked on the paper's patterns (the reference directors are
// perpendicular to the vertex's OUTGOING edge, not to the edge of the same list index, and
// the rest lengths match the outgoing edges): every per-edge quantity (twist angle t of *Q,
// *RL, *RefD1) is stored with the edge's start vertex; every per-vertex quantity (*RK, *RT,
// *RefT) belongs to the joint between the vertex's incoming and outgoing edges.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace yarnhom::yarn {

// Bounds a pattern read from a file must respect (checked by parse_pyp, which names the rule
// and the line): no textile comes near them, a broken or mis-scaled file does. The paper's
// patterns have radii 1e-4..1e-3 m, periods 4.4..17.4 radii, edges 0.53..2.7 radii, twist
// angles within 1.2 rad, rest curvatures within 1.04, rest and reference twists within 1.8 rad,
// directors within 6 degrees of perpendicular to their edges.
inline constexpr double kMinRadius = 1e-6, kMaxRadius = 1e-2;  // m
inline constexpr double kMinEdge = 0.01, kMaxEdge = 100;        // yarn radii (edges, rest lengths)
inline constexpr double kMaxAngle = 100;                        // rad, |t|
inline constexpr double kMaxRestCurvature = 10;                 // |RK| (2 tan of half the turning angle)
inline constexpr int kMaxVertices = 1000000;

struct PatternEdge {
  int v0 = 0, v1 = 0;  // edge vector = x[v1] + (dx px, dy py, 0) - x[v0]
  int dx = 0, dy = 0;
};

struct Pattern {
  std::string name;    // file stem or generator name; used in messages and outputs
  std::string source;  // the file it was read from ("" when generated): named in error messages
  double px = 0, py = 0, radius = 0;
  std::vector<Eigen::Vector3d> x;           // *Q x y z (m)
  std::vector<double> theta;                // *Q t: twist angle of the vertex's outgoing edge
  std::vector<PatternEdge> edges;           // *E, in file order
  std::vector<double> rest_length;          // *RL, per vertex (its outgoing edge), m
  std::vector<Eigen::Vector2d> rest_kappa;  // *RK, per vertex, material curvatures (1)
  std::vector<double> rest_twist;           // *RT, per vertex (rad)
  std::vector<Eigen::Vector3d> ref_d1;      // *RefD1, per vertex (its outgoing edge)
  std::vector<double> ref_twist;            // *RefT, per vertex (rad)
  int size() const { return static_cast<int>(x.size()); }
};

// The file a pattern came from, else its name: what messages name.
inline std::string display_name(const Pattern& p) { return p.source.empty() ? p.name : p.source; }

// Closed-yarn structure derived from the edges: every vertex has exactly one outgoing and
// one incoming edge (checked when reading).
struct Topology {
  std::vector<int> next, prev;           // along the yarn
  std::vector<Eigen::Vector2i> offset;   // tile offset of next[v] as seen from v
  std::vector<std::vector<int>> yarns;   // vertices of each closed yarn, in order
  std::vector<int> yarn_of;              // yarn index of each vertex
};
Topology topology(const Pattern& p);

// Edge vector of the outgoing edge of v in the stored geometry.
Eigen::Vector3d stored_edge(const Pattern& p, const Topology& t, int v);

// Parses .pyp text; `file` names the source in messages ("basket.pyp: line 12: ...").
// Blocks *pattern, *Q, *E are required; *RL, *RK, *RT, *RefD1, *RefT are optional and, when
// all are absent, filled from the stored geometry by complete_rest_state.
Pattern parse_pyp(const std::string& text, const std::string& file);
Pattern read_pyp(const std::string& path);
std::string format_pyp(const Pattern& p);
void write_pyp(const std::string& path, const Pattern& p);

// Fills the rest state from the stored geometry: rest lengths = edge lengths, reference
// directors by parallel transport along each yarn, reference twists to match, zero rest
// curvature and rest twist (a straight, untwisted yarn at rest, like the tiny patterns).
void complete_rest_state(Pattern& p);

// Tiles the pattern nx x ny times (a larger RVE of the same material).
Pattern tile(const Pattern& p, int nx, int ny);

}  // namespace yarnhom::yarn
