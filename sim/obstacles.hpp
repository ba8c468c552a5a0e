#pragma once
// Colliders that are surfaces rather than a signed distance (sim/collider.hpp keeps the plane
// and the sphere): capsules (a segment with a radius: an arm, a rod, a mannequin's limbs) and
// triangle meshes, static or moving. They meet the cloth through the same contact pairs as the
// cloth meets itself (sim/contact.hpp): IPC's barrier on point-triangle and edge-edge
// distances, CCD, lagged friction.
//
// All obstacles together are one point set y (3K, obstacle-major) with edges and triangles on
// it: a capsule is two points and one edge with its radius (the barrier acts at radius + d_hat
// from the axis, never inside the radius); a mesh contributes its vertices, edges and
// triangles (radius 0). Positions depend on time: a capsule translates along keyframes
// (t, dx, dy, dz) like a handle (sim/handles.hpp); a mesh interpolates linearly between its
// frames (OBJ files, one per `frame_dt` seconds; held at the last).
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace yarnhom::sim {

struct CapsuleObstacle {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::UnitX();  // axis ends at t = 0, m
  double radius = 0.01;                                                      // m
  double friction = 0;                                                       // Coulomb mu with the cloth
  std::vector<std::array<double, 4>> path;  // (t, dx, dy, dz) offsets, piecewise linear; empty: static
};

struct MeshObstacle {
  std::string name;                       // for messages (the OBJ file)
  std::vector<std::string> files;         // the OBJ files it was read from (absolute), one per frame; empty: made in code
  double scale = 1;                       // what read_mesh_obstacle applied to the files' positions
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::MatrixX3i tris;                  // triangles over the frames' vertices
  std::vector<Eigen::MatrixX3d> frames;   // >= 1; all with the same vertex count, m
  double frame_dt = 1.0 / 30;             // s between frames
  double friction = 0;
};

// The primitives of every obstacle on the point set y.
struct ObstacleSet {
  std::vector<CapsuleObstacle> capsules;
  std::vector<MeshObstacle> meshes;
  // Built by finish_obstacles: per point / edge / triangle, its radius and friction.
  std::vector<Eigen::Vector2i> edges;
  std::vector<Eigen::Vector3i> tris;
  std::vector<double> edge_radius, edge_friction, tri_friction, point_friction;
  std::vector<char> point_on_mesh;  // 1: a mesh vertex (used in point-triangle pairs); 0: a capsule's end
  int num_points = 0;
  bool empty() const { return capsules.empty() && meshes.empty(); }
  bool moving() const;
};

// Fills the primitive lists from capsules and meshes (edges of a mesh once each).
void finish_obstacles(ObstacleSet& o);

// y (3K) at time t.
Eigen::VectorXd obstacle_positions(const ObstacleSet& o, double t);

// A mesh obstacle from OBJ files (one, or a sequence of frames with the same faces); the `v`
// lines in metres, scaled by `scale` and moved by `offset`. Throws naming the file and what is
// wrong (unreadable, no triangles, a frame whose vertex count or faces differ).
MeshObstacle read_mesh_obstacle(const std::vector<std::string>& files, double frame_dt, double scale = 1.0,
                                const Eigen::Vector3d& offset = Eigen::Vector3d::Zero());

// Capsules as one static mesh obstacle: each a closed, outward-oriented triangle mesh with its
// vertices on the capsule's surface (`around` vertices per ring, `rings` rings per half sphere
// and the two poles), placed where the capsule is at t = 0; the shells of overlapping capsules
// overlap. The mannequin as an OBJ body (tests, sim/garment.hpp).
MeshObstacle capsules_mesh(const std::vector<CapsuleObstacle>& capsules, int around = 24, int rings = 6);

// One frame of a mesh obstacle as an OBJ file (positions and triangles; atomically).
void write_obstacle_obj(const std::string& path, const MeshObstacle& m, size_t frame = 0);

}  // namespace yarnhom::sim
