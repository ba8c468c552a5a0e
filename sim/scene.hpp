#pragma once
// A simulation scene: the mesh and where it starts, prescribed vertices, colliders, forces,
// the integrator and the frames to write. Built in (drape, hang, stretch: docs/sim.md) or
// read from a JSON file (sim/scene_json.hpp). The material is not part of the built-in scenes
// (the command's --material); a scene file may name one.
#include <optional>
#include <string>
#include <vector>

#include "sim/collider.hpp"
#include "sim/handles.hpp"
#include "sim/mesh.hpp"
#include "sim/newton.hpp"
#include "sim/obstacles.hpp"
#include "sim/problem.hpp"

namespace yarnhom::sim {

// Newton: implicit Euler solved by Newton; Linearized: one Newton iteration of it (one solve);
// BaraffWitkin: ARCSim-HYLC's one-solve step (sim/integrators.hpp); Static: load steps.
enum class Integrator { Newton, Linearized, BaraffWitkin, Static };
Integrator parse_integrator(const std::string& name);  // "newton", "linearized", "baraff-witkin", "static"
const char* integrator_name(Integrator i);

// The stretch test's report (spec section 11): the reaction of the moving clamp along the
// axis divided by the undeformed width, per load step.
struct StretchReport {
  bool enabled = false;
  size_t moving_handle = 0;  // index into Scene::handles
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  double length = 0, width = 0;  // undeformed, m
  Eigen::Vector2d middle = Eigen::Vector2d::Zero();  // rest point whose triangle is "the middle"
};

struct Scene {
  std::string name;
  Mesh mesh;                              // positions = where it starts
  std::string material;                   // file, "" = the command's --material
  std::optional<double> areal_density;    // kg/m^2, overrides the material's
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);
  std::vector<Handle> handles;            // pins and moving handles
  std::vector<Collider> colliders;
  ObstacleSet obstacles;                  // capsules and mesh colliders (sim/obstacles.hpp)
  bool self_collision = true;             // the cloth against itself (sim/contact.hpp)
  double self_friction = -1;              // mu between cloth layers; < 0: the scene's global friction
  std::vector<Stitch> stitches;           // seams (sim/garment.hpp); offset0 filled from the start positions
  double stitch_stiffness = 0;            // N/m per stitch
  double sew_time = 0.5;                  // s
  double gravity_delay = 0;               // s: no gravity before (a garment is sewn weightless)
  double dhat = 1e-3;                     // m
  double kappa = 0;                       // Pa; 0 = 100 x areal density x |g|
  double rayleigh_alpha = 0, rayleigh_beta = 0, air_drag = 0;
  double friction_eps_v = 0;              // m/s, friction's sticking velocity; 0 = 1e-3 l per second
  int friction_updates = 0;               // IPC's lag updates per step (sim/friction.hpp)
  Integrator integrator = Integrator::Newton;
  double dt = 1.0 / 30;                   // s per frame
  int substeps = 1;                       // steps per frame
  int frames = 90;                        // frames after the initial one
  NewtonSettings newton;                  // tol_step 0: 1e-2 l h (dynamic), 1e-8 l (static); l = rest diagonal
  std::vector<int> render_frames;         // frames drawn as PNG
  StretchReport stretch;
};

// Built-in scenes. resolution: quads along the longer side (0 = the scene's default).
// drape: a 0.5 m square sheet, 5 cm above a sphere of radius 0.15 m (and the floor below it),
//   falls and drapes; 90 frames of 1/30 s; friction mu = 0.3 with both (cloth on a smooth solid).
// hang: a 0.5 m square sheet held horizontally by two adjacent corners, released; it swings
//   down and hangs; 90 frames of 1/30 s.
// fold: a 0.4 m square sheet falls onto a thin rod (a capsule lying on the floor) and its left
//   half is folded over the rod onto its right half by a handle on its left edge (self-contact).
// tshirt: a T-shirt made by the program, sewn on a mannequin of capsules (sim/garment.hpp).
// stretch: a 5 cm x 10 cm strip, long axis along the course (x) or the wale (y), both short
//   ends clamped (every vertex within 5 mm of the end fixed in all three coordinates, the yarn
//   strip's clamp band), the far clamp moved
//   quasi-statically from 100 % to 170 % of the length in 5 % steps (14 load steps), no
//   gravity. StretchSize changes the strip's size and its last stretch and load steps (the
//   strip-width study compares yarn and continuum strips of other sizes); the resolution is
//   then quads across the width, by default one per 5 mm.
struct StretchSize {
  double width = 0.05, length = 0.10;  // metres
  double last = 1.7;                   // the last stretch ratio (clamp separation / length)
  int steps = 14;                      // load steps from 100 % to `last`, evenly spaced
  // Clamp band at each short end, metres: every vertex within it is held, as `yarnhom strip`
  // holds every yarn vertex within its --clamp of the ends (docs/strip.md section 3); 0: the
  // end row only.
  double clamp = 0.005;
};
Scene builtin_scene(const std::string& name, int resolution = 0, char direction = 'x', const StretchSize& size = {});
bool is_builtin_scene(const std::string& name);

// The triangle that contains (or is nearest to) a rest point.
int triangle_at(const Mesh& mesh, const Eigen::Vector2d& rest_point);

}  // namespace yarnhom::sim
