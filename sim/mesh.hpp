#pragma once
// The cloth's triangle mesh (spec section 10): rest positions in the material plane (metres,
// x = course, y = wale), triangles counterclockwise in that plane, and for every triangle the
// three "flap" vertices across its edges, which the discrete second fundamental form needs.
//
// Edge i of triangle (v0, v1, v2) runs from v_i to v_{i+1}; flaps(t, i) is the vertex of the
// other triangle on that edge, or -1 on a boundary edge (where bending contributes nothing).
#include <Eigen/Core>
#include <string>

namespace yarnhom::sim {

struct Mesh {
  Eigen::MatrixX2d rest;   // [n, 2] material coordinates, m
  Eigen::MatrixX3d x;      // [n, 3] initial positions, m
  Eigen::MatrixX3i tris;   // [m, 3] counterclockwise in the material plane
  Eigen::MatrixX3i flaps;  // [m, 3] vertex across edge i, -1 on a boundary

  int num_vertices() const { return int(rest.rows()); }
  int num_triangles() const { return int(tris.rows()); }
};

// Fills flaps from tris. Throws std::invalid_argument (prefixed by `where`) when an edge has
// more than two triangles or two triangles run through an edge in the same direction (the
// mesh is not an oriented manifold), or a vertex index is out of range.
void build_flaps(Mesh& mesh, const std::string& where = "mesh");

// Checks sizes, finiteness and that every triangle has positive rest area (counterclockwise in
// the material plane); triangles that are all clockwise are flipped first, a mix is refused.
// Then builds the flaps. `where` names the source in messages.
void finish_mesh(Mesh& mesh, const std::string& where = "mesh");

// Lumped vertex areas: each triangle's rest area split equally among its three vertices.
Eigen::VectorXd vertex_areas(const Mesh& mesh);

}  // namespace yarnhom::sim
