#pragma once
// Reading the geometry that `strip` (yarn centrelines, OBJ polylines) and `sim` (the continuum
// surface, OBJ triangles) write, for the accuracy metrics. Only what the metrics need: vertex
// positions, faces (polygons fanned into triangles) and polylines; texture coordinates and
// normals are skipped.
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace yarnhom {

struct ObjGeometry {
  Eigen::Matrix3Xd V;                    // vertex positions (the file's units)
  Eigen::Matrix3Xi F;                    // triangles, 0-based
  std::vector<std::vector<int>> lines;   // polylines, 0-based
  std::vector<std::string> line_groups;  // per polyline, the group ("g NAME") it was read in; "" before any
};

// The vertices of the polylines outside `group` (strip's centrelines: the fabric's own yarn
// without its soft "boundary" yarn). All vertices when the file has no polyline of that group.
Eigen::Matrix3Xd points_outside_group(const ObjGeometry& g, const std::string& group);

// Throws FileError naming the file and line for what it cannot read (a bad number, an index out
// of range).
ObjGeometry read_obj_geometry(const std::string& path);

}  // namespace yarnhom
