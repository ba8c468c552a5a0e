#pragma once
// A yarn-level fabric strip (docs/strip.md): ONE yarn made of a tiled periodic pattern whose
// loose ends are joined by boundary yarn (yarn/strip/strip_generate.hpp), with the rest state of a
// discrete elastic rod along it.
//
// Indexing along the yarn: vertices 0..n-1; edge i joins vertex i to i+1 (and n-1 to 0 when
// the yarn is closed), its data stored with i like the pattern's (twist angle, rest length,
// reference director); joint i sits at vertex i, between edges i-1 and i (an open yarn has no
// joint at its two ends).
//
// Coordinates are the pattern's: x along the course, y along the wale, z out of the fabric.
// The nominal strip is the rectangle |x| <= extent_x/2, |y| <= extent_y/2; its long axis is x
// for a course test and y for a wale test.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace yarnhom::yarn {

enum class StripAxis { kCourse, kWale };
const char* to_string(StripAxis a);

// Where a strip vertex came from: a vertex of the tiled pattern (pattern vertex index and the
// tile cell whose copy it is: position = pattern x + (cell_x px, cell_y py, 0)), or -1 for a
// vertex the boundary yarn added.
struct StripSource {
  int vertex = -1;
  int cell_x = 0, cell_y = 0;
};

struct Strip {
  std::string name;   // "<pattern>_<course|wale>"
  double radius = 0;  // yarn radius (m)
  double width = 0, length = 0;  // nominal size (m): across and along the long axis
  StripAxis axis = StripAxis::kCourse;
  double connector_scale = 1.0 / 200;  // boundary yarn moduli / the yarn's
  bool closed = false;

  std::vector<Eigen::Vector3d> x;  // per vertex (m)
  std::vector<StripSource> source;  // per vertex

  // per edge
  std::vector<double> theta;            // twist angle of the material frame (rad)
  std::vector<double> rest_length;      // m
  std::vector<Eigen::Vector3d> ref_d1;  // reference director, perpendicular to the edge
  std::vector<unsigned char> connector_edge;  // 1: boundary yarn (scaled stretching modulus)

  // per vertex (joint); ignored at the ends of an open yarn
  std::vector<Eigen::Vector2d> rest_kappa;  // rest material curvatures (1)
  std::vector<double> rest_twist;           // rad
  std::vector<double> ref_twist;            // reference twist of the stored frames (rad)
  std::vector<unsigned char> connector_joint;  // 1: boundary yarn (scaled bend and twist)

  // What the generator did (for reports): tiles covering the strip, yarn rows kept (courses /
  // wefts / warps running through the strip), boundary rows added (knits: the soft course
  // above and below that binds the loops off), connectors (selvedge turns and corners), and
  // the vertices of the tiling inside the strip's rectangle that were dropped with the rows
  // they belong to (pieces of outside rows poking into the strip: too short to carry load).
  int tiles_x = 0, tiles_y = 0;
  int rows = 0, boundary_rows = 0, connectors = 0, dropped_vertices = 0;
  // The width of fabric the load-bearing rows stand for: the rows running along the long axis
  // (wefts of a course test, warps of a wale test, courses of a knit's course test), each one
  // row spacing of the tiling (the across period / that direction's rows per tile). Rows are
  // whole, so this differs from the nominal width by up to a row: basket course, 18 wefts of
  // 2.68 mm = 48.2 mm for 50 mm. Without rows along the long axis (a knit's wale test) it is
  // the nominal width. The clamp force per this width is the fabric's N/m (docs/strip.md).
  double load_width = 0;

  int size() const { return static_cast<int>(x.size()); }
  int num_edges() const { return closed ? size() : size() - 1; }
  bool has_joint(int v) const { return closed || (v > 0 && v < size() - 1); }
  int next(int v) const { return v + 1 < size() ? v + 1 : 0; }
  int prev(int v) const { return v > 0 ? v - 1 : size() - 1; }
  // Unit vector of the long axis (x for a course test, y for a wale test).
  Eigen::Vector3d long_axis() const {
    return axis == StripAxis::kCourse ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  }
  double extent_x() const { return axis == StripAxis::kCourse ? length : width; }
  double extent_y() const { return axis == StripAxis::kCourse ? width : length; }
};

// Makes the boundary yarn (or, with all = true, the whole strip) stress-free at its present
// shape: rest lengths = edge lengths, rest curvatures and twists = the material curvatures and
// twists measured with the stored frames (ref_d1, theta, ref_twist).
void set_rest_to_shape(Strip& s, bool all = false);

// Checks the invariants every strip satisfies (sizes of the per-edge and per-joint arrays,
// unit directors perpendicular to their edges, positive rest lengths); throws
// std::invalid_argument naming the first violation.
void check_strip(const Strip& s);

}  // namespace yarnhom::yarn
