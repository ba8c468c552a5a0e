#pragma once
// Wavefront OBJ in: the one reader for every OBJ the program takes or reads back (the
// continuum simulator's meshes, the accuracy metrics' surfaces and yarn centrelines).
// `v x y z` positions, `vt u v` texture coordinates, `f` faces with `v`, `v/vt`, `v/vt/vn` or
// `v//vn` corners (polygons are split into fans; negative indices count back from the last
// element defined so far), `l` polylines and `g NAME` groups. Normals are skipped.
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace yarnhom {

struct ObjGeometry {
  Eigen::Matrix3Xd V;                    // vertex positions (the file's units)
  Eigen::Matrix3Xi F;                    // triangles, 0-based
  Eigen::Matrix2Xd T;                    // texture coordinates
  Eigen::Matrix3Xi FT;                   // per triangle corner, its texture index; -1 where none
  std::vector<int> face_line;            // per triangle, the line of the file it came from
  std::vector<std::vector<int>> lines;   // polylines, 0-based
  std::vector<std::string> line_groups;  // per polyline, the group ("g NAME") it was read in; "" before any
};

// The vertices of the polylines outside `group` (strip's centrelines: the fabric's own yarn
// without its soft "boundary" yarn). All vertices when the file has no polyline of that group.
Eigen::Matrix3Xd points_outside_group(const ObjGeometry& g, const std::string& group);

// Throws FileError for what it cannot read, its message naming the file and line as
// "FILE:LINE: problem" (a bad number, an index out of range, a face with fewer than 3 corners).
ObjGeometry read_obj_geometry(const std::string& path);

}  // namespace yarnhom
