#pragma once
// A generated rectangular sheet: width (along x = course) by height (along y = wale), nx by ny
// quads, each split into two triangles with the diagonal alternating in a checkerboard, so
// that the triangulation has no preferred diagonal direction (a single diagonal direction
// makes discrete bending stiffer along it).
#include "sim/mesh.hpp"

namespace yarnhom::sim {

// Rest positions (i w/nx, j h/ny); positions the same in the plane z = 0. Vertex (i, j) has
// index j (nx + 1) + i.
Mesh make_rectangle(double width, double height, int nx, int ny);

inline int rectangle_vertex(int nx, int i, int j) { return j * (nx + 1) + i; }

}  // namespace yarnhom::sim
