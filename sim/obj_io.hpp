#pragma once
// Wavefront OBJ in and out. In: `v x y z` positions, `vt u v` texture coordinates, which are
// the rest positions in the material plane (u = course, v = wale), and `f` faces with `v/vt`
// corners (polygons are split into fans). The texture coordinates are in metres (HYLC's and
// ARCSim-HYLC's convention), unless the file carries the line
//   # yarnhom uv: rest_m = origin + scale * vt; origin OU OV scale S
// as every OBJ yarnhom writes does: then the rest position is (OU + S u, OV + S v) (docs/sim.md,
// "Outputs"). Every vertex must carry one texture coordinate (a seam, i.e. a vertex with two
// different texture coordinates, is refused: the simulator has one rest position per vertex).
#include <string>

#include "sim/mesh.hpp"

namespace yarnhom::sim {

// Throws std::invalid_argument naming the file and line on any problem.
Mesh read_obj(const std::string& path);

// Writes positions, texture coordinates in [0, 1] (the rest positions shifted and scaled by one
// factor, aspect kept; the "# yarnhom uv:" line says how) and the triangles; atomically.
void write_obj(const std::string& path, const Mesh& mesh, const Eigen::MatrixX3d& x);

// The rest shape as a mesh of its own: positions (rest_u, rest_v, 0) in metres, the same texture
// coordinates and triangles as write_obj (OUT/rest.obj of a simulation).
void write_rest_obj(const std::string& path, const Mesh& mesh);

}  // namespace yarnhom::sim
