#pragma once
// The collapse guard: what makes a state no fabric reaches unreachable for the simulator.
//
// A knit jams before a triangle of it is sheared flat (|s_a| -> 1), before a direction of it is
// crushed to nothing (s_x or s_y -> -1), before its yarns are pulled straight and before it is
// bent to a radius of its own thickness.
// A baked table's safeguard (docs/bake.md) continues the data beyond its box to second order at
// most, so the tables alone leave those states at a finite energy: a one-solve time step that
// lands near one of them finds nothing to push it back (issue 38: a drape stopped on a triangle
// at s_a = -0.9996, where the tables' energy was 4.98 J/m^2). The guard adds to the material
//
//   G(s) = k [ psi(z_xl) + psi(z_xh) + psi(z_yl) + psi(z_yh) + psi(z_al) + psi(z_ah) ] + k [ psi(z_1) + psi(z_2) ],
//   psi(z) = z^3 / (1 - z)^2 for 0 <= z < 1,  0 for z <= 0,  +inf for z >= 1,
//
// with z the distance beyond the box's edge in units of the distance from that edge to collapse:
//   z_xl = (x_lo - s_x) / (1 + x_lo),  z_xh = (s_x - x_hi) / (1 + x_hi),
//   z_al = (a_lo - s_a) / (1 + a_lo),  z_ah = (s_a - a_hi) / (1 - a_hi)
// (s_y likewise: a stretch ratio of twice the box's largest is out of reach), and per principal
// curvature l_i of K = [[II_x, II_a], [II_a, II_y]]
//   z_i = (|l_i| - c) / (c_lim - c),  c = the bending boxes' largest bound, c_lim = 10.5 c
// (a fold radius of a tenth of the box's tightest, about the fabric's thickness). The curvature
// part is tr g(K) with g(l) = k psi(z(l)), mixed exactly as the bending terms are (material.hpp,
// umbilic points included), so it depends on the curvature tensor alone, not on its axes.
//
// Properties (tests/material/test_collapse_guard.cpp): zero with its gradient and Hessian
// everywhere inside the box (the tables are untouched there), C2 at the box's edges (psi, psi',
// psi'' vanish at z = 0), convex in each of its variables (psi'' = 6z/(1-z)^4 >= 0), third
// derivative 6 k / w^3 at the edge (w the edge-to-collapse width) and bounded wherever z stays
// below 1, and unbounded towards collapse: psi(0.9) = 73, psi(0.99) = 9.7e3. So the total is
// bounded below on the reachable domain, whatever a 2D table's first-order continuation does
// there (a bilinear corner of a stretch-bending pair falls without bound along one diagonal
// where the tables alone are continued). k is the largest
// energy above rest the material itself reaches on its in-plane box, so along s_a -> 0.999 the
// guard is five orders of magnitude above anything inside.
#include <functional>
#include <string>

#include "material/material.hpp"

namespace yarnhom {

// The box the guard surrounds: the in-plane 1D boxes and the bending boxes' largest |bound|.
struct GuardBox {
  double lo[3] = {-0.2, -0.7, -0.2};  // s_x, s_a, s_y (docs/conventions.md section 2's defaults)
  double hi[3] = {1.0, 0.7, 1.0};
  double curvature = 200;             // 1/m
};

struct CollapseGuard {
  GuardBox box;              // after clamping: shear edges within [-0.9, 0.9], stretch edges in [-0.6, 3]
  double curvature_limit = 0;  // c_lim (1/m)
  double scale = 0;            // k (J/m^2); 0: no guard
};

// The guard around `box` for a material whose largest energy above rest on that box (at zero
// curvature and at the bending bounds) is taken from `psi` itself. Edges beyond the clamps above
// (a HYLC file whose knots were extended past the box) are pulled in to them.
CollapseGuard make_collapse_guard(const GuardBox& box, const std::function<MaterialEval(const Strain6&)>& psi);

// The guard of a baked material: its terms' boxes (defaults for a missing term).
GuardBox baked_guard_box(const BakedMaterial& mat);

// psi(z) and its first three derivatives (z < 1; +inf beyond).
struct GuardJet {
  double v, d1, d2, d3;
};
GuardJet guard_profile(double z);

// Adds G(s) with its gradient and Hessian to e. Outside the physical domain (|s_a| >= 1, s_x or
// s_y <= -1) the value is +inf.
void add_collapse_guard(const CollapseGuard& g, const Strain6& s, MaterialEval& e);
// psi plus the guard's value: bit for bit what add_collapse_guard makes of e.psi == psi.
double add_collapse_guard_value(const CollapseGuard& g, const Strain6& s, double psi);

// One line for logs: "collapse guard: k = ... J/m^2 beyond s_x < ..., ...".
std::string describe(const CollapseGuard& g);

}  // namespace yarnhom
