#pragma once
// Wavefront OBJ in and out. In: `v x y z` positions, `vt u v` texture coordinates, which are
// the rest positions in the material plane in metres (HYLC's and ARCSim-HYLC's convention:
// u = course, v = wale), and `f` faces with `v/vt` corners (polygons are split into fans).
// Every vertex must carry one texture coordinate (a seam, i.e. a vertex with two different
// texture coordinates, is refused: the simulator has one rest position per vertex).
#include <string>

#include "sim/mesh.hpp"

namespace yarnhom::sim {

// Throws std::invalid_argument naming the file and line on any problem.
Mesh read_obj(const std::string& path);

// Writes positions, the rest positions as texture coordinates and the triangles; atomically.
void write_obj(const std::string& path, const Mesh& mesh, const Eigen::MatrixX3d& x);

}  // namespace yarnhom::sim
