#pragma once
// Scene files (JSON), the format of docs/sim.md:
//   {
//     "mesh": {"obj": "cloth.obj"} | {"rectangle": {"width": 0.5, "height": 0.5, "nx": 40, "ny": 40}}
//           | {"garment": "tshirt", "resolution": 4, "mannequin": false},  (sim/garment.hpp: panels,
//             stitches and sewing; the body from "colliders", placed in the mannequin's frame)
//     "position": {"rotate_deg": [rx, ry, rz], "translate": [x, y, z]},      (optional; not with a garment)
//     "material": "baked.h5" | "hylc.json",                                   (optional)
//     "areal_density": 0.3, "gravity": [0, 0, -9.81],
//     "pins": [SELECTION, ...],
//     "handles": [{"select": SELECTION, "path": [[t, dx, dy, dz], ...]}, ...],
//     "colliders": [{"sphere": {"center": [..], "radius": r}, "friction": 0.3}, {"plane": {"point": [..], "normal": [..]}}],
//     "colliders": [... {"capsule": {"a": [..], "b": [..], "radius": r, "path": [[t, dx, dy, dz], ...]}},
//                   {"mesh": {"obj": "body.obj" | "frames": ["f0.obj", ...], "frame_dt": 0.0333,
//                             "scale": 1, "translate": [x, y, z]}}],          (sim/obstacles.hpp)
//     "self_collision": true | false | {"enabled": true, "friction": 0.2},   (default on; friction: the global one)
//     "seams": {"stitches": [[a, b], ...], "stiffness": 50, "sew_time": 0.5, "gravity_delay": 0},  (sim/garment.hpp;
//               with a garment: its stitches and sewing unless given, "stitches" added to its own)
//     "barrier": {"dhat": 1e-3, "kappa": 100},
//     "friction": 0.3 | {"mu": 0.3, "eps_v": 7e-4, "updates": 0},      (colliders without their own)
//     "damping": {"rayleigh_alpha": 0, "rayleigh_beta": 0, "air": 0},
//     "integrator": "newton" | "linearized" | "baraff-witkin" | "static",
//     "dt": 0.0333, "substeps": 1, "frames": 90,
//     "newton": {"tolerance": 1e-6, "tolerance_norm": "rms" | "max" | "auto", "max_iterations": 100},
//     "render": [0, 30, 90],
//     "stretch_report": {"handle": 1, "axis": [1, 0, 0], "length": 0.1, "width": 0.05, "middle": [0.05, 0.025]}
//   }
// SELECTION = {"vertices": [i, ...]} (0-based) or {"rest_box": [u0, v0, u1, v1]} (every vertex
// whose rest position lies in the box, metres). Paths are relative to the scene file.
// Friction (sim/friction.hpp): a collider's own "friction" (mu >= 0), else the global one, else
// 0 (frictionless); eps_v (m/s, default 1e-3 sheet diagonals per second) and updates (IPC's
// lag updates per step, default 0) only in the global object form.
// Unknown keys and wrong types are refused, naming the file and the key.
#include <string>

#include "sim/scene.hpp"

namespace yarnhom::sim {

Scene read_scene_json(const std::string& path);

}  // namespace yarnhom::sim
