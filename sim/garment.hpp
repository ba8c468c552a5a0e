#pragma once
// Garments: panels sewn along seams, and the built-in T-shirt on a mannequin of capsules.
//
// Seams: a stitch joins vertex a of one panel to vertex b of another with the spring energy
//   E = k/2 |x_a - x_b - g(t) o|^2,   g(t) = max(0, 1 - t / T_sew),   o = x_a - x_b at t = 0,
// a zero-rest-length spring whose target offset fades from the panels' starting gap to 0 over
// the sewing time T_sew: the panels are pulled together smoothly in the first frames and held
// sewn after (a quadratic in x: its Hessian k [I -I; -I I] is PSD as it stands). Stitched
// vertices share a representative (Problem::vertex_rep): contact pairs between primitives whose
// vertices are stitched to each other are skipped, as pairs sharing a vertex are, so the seam's
// two sides may meet.
//
// The T-shirt (`yarnhom sim tshirt`): front and back panels of one T-shaped pattern (torso 0.48 m
// wide and 0.64 m high, sleeves 0.40 m long and 0.32 m wide), meshed on a square grid of spacing
// 0.08 m / k, the back panel mirrored so both faces point outward; they start flat 16 cm in
// front of and behind a mannequin of capsules (torso, neck, arms held out) and are sewn at the
// sides and under the arms, and along the shoulders and the sleeves' tops (the neck, hem and
// sleeve ends stay open) over the first 0.5 s, weightless
// while it is sewn (Scene::gravity_delay: gravity acts from 0.5 s on). k = 9 gives 14.7k
// vertices, the paper's size (k = 4, the default: 3,010).
//
// The mannequin's frame, where a body OBJ worn by the T-shirt must stand (scene files'
// "mesh": {"garment": "tshirt"} with the body in "colliders", or `sim tshirt --body FILE.obj`):
// metres, z up, facing +y (the front panel starts at y = +0.16, the back at y = -0.16), the
// torso's axis on x = y = 0; the mannequin's torso is a capsule of radius 0.12 m from z = 0.80
// to 1.34 m, its arms held out sideways (T pose) on z = 1.34 m (radius 4 cm, hands at
// |x| = 0.74 m), its neck up to z = 1.68 m. The panels span |x| < 0.64 m (sleeves from
// z = 1.18 m, torso |x| < 0.24 m from the hem at z = 0.86 m) up to z = 1.50 m: a body must lie
// between them there (|y| < 0.15 m) to start clear of the cloth.
#include <Eigen/Sparse>
#include <vector>

#include "sim/problem.hpp"
#include "sim/scene.hpp"

namespace yarnhom::sim {

// The seam energy at time t; gradient added to grad (3n), Hessian triplets (lower, free unknowns).
double seam_energy(const Problem& P, const std::vector<int>& free_index, const Eigen::VectorXd& x, double t,
                   Eigen::VectorXd* grad = nullptr, std::vector<Eigen::Triplet<double>>* triplets = nullptr);

// Representatives: stitched vertices (transitively) share the smallest index among them.
std::vector<int> stitch_representatives(int num_vertices, const std::vector<Stitch>& stitches);

// The T-shirt's panels, seams and sewing (mesh, stitches, stitch_stiffness, sew_time,
// gravity_delay) at grid refinement k >= 1 (spacing 0.08 m / k), with no body.
Scene tshirt_garment(int k);

// The mannequin of capsules (torso, neck, arms held out), friction 0.3.
std::vector<CapsuleObstacle> mannequin_capsules();

// The built-in T-shirt: tshirt_garment(k) on the mannequin, friction 0.2 between its layers,
// 90 frames.
Scene tshirt_scene(int k);

// Throws std::invalid_argument naming body.name when a vertex of the body's first frame lies
// where the T-shirt's panels start (within 1 cm of, or beyond, a panel over its outline).
void check_body_clear_of_tshirt(const MeshObstacle& body);

}  // namespace yarnhom::sim
