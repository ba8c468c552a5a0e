#pragma once
// The time steppers and the static solve (spec section 10).
//
// implicit_euler_step: x_{n+1} = argmin Phi (sim/potential.hpp) by Newton with line search;
//   v_{n+1} = (x_{n+1} - x_n)/h. Prescribed vertices are placed at their targets for t_{n+1}.
//   Newton starts from the inertial prediction x_n + h v_n (a vertex whose move would enter a
//   collider stays), or from x_n where that has the lower Phi (sim/integrators.cpp says why).
// linearized_step: the one-solve step (`--integrator linearized`): the same step with exactly one
//   Newton iteration -- one assembly, one factorization, one solve -- then the collider-filtered
//   Armijo line search on Phi (energy evaluations only). It is implicit Euler linearized at the
//   predicted state, and the line search makes it stable: Phi(x_{n+1}) <= Phi(start) <= T_n + E_n,
//   so no step creates energy, where the unguarded linear step (below) overshoots a soft knit's
//   curl or shear into collapse at dt = 1/30 s. Colliders and friction act as in the Newton step
//   (barrier, lagged friction). Its prescribed vertices are not placed at their targets first:
//   they move within the solve, with the cloth's first-order response (newton_minimize's target,
//   sim/newton.hpp); a move cut short goes on in another solve (at most max_stages), the rest
//   lags to the next step. (Placed first, a handle moving 1.5 quads per step left its
//   neighbours behind, the one solve never caught up, and the fold scene's start went past the
//   collapse guard: non-finite at step 16.) In a step whose obstacles move, the contact pairs'
//   friction takes its majorizing Hessian (sim/contact.hpp: pair_friction_energy) and a solve
//   whose line search took less than the whole Newton step gets up to three more iterations
//   (NewtonSettings::extra_when_cut): a seam sliding on a moving arm has no friction stiffness
//   along its slip, its Newton step was 30 cm on a 1.7 cm step, CCD against the body cut the
//   whole step to 1-40 %, and the cloth, keeping that share of its correction step after step,
//   stretched (GarmentBody.OneSolveStepCarriesTheTshirtOnABodyMovingSideways). The same extra
//   iterations go to a step with contact that ends before the sewing time (P.sew_time) with
//   gravity acting: the half-sewn shirt falling onto a still body had its step cut to 5-32 % by
//   CCD and stretched to |s| 1.84, non-finite once the body moved
//   (GarmentBody.OneSolveStepTakesExtraIterationsWhileTheSeamsCloseUnderGravity). Other steps
//   whose obstacles stand still are unchanged, bit for bit.
// Contact (sim/contact.hpp: self-collision and obstacles), in both: the move from x_n to
// Newton's start (the prediction, handles and obstacles moved to their targets) is made safe by
// make_move_safe (vertices that would pass through cloth stay, those an obstacle would pass
// through are carried along, and push the cloth they would pass through along with them,
// unless that pinches them against a collider or another obstacle);
// when that is not enough, the step goes in stages: everything moves by 0.9 of the safe
// fraction (contact and colliders), Newton solves there, and the next stage starts from its
// solution, at most ObstacleMotion::max_stages times; a stage that cannot move at all ends the
// step where the last one did. Every Newton and line-search step is CCD-limited, so the cloth
// never crosses itself or an obstacle.
// baraff_witkin_step: ARCSim-HYLC's integrator (Baraff and Witkin 1998), kept for comparison
//   with it (`--integrator baraff-witkin`): one linear solve, no line search,
//     (M (1 + h alpha) + h (h + beta) K + h C_air) dv = h (f - alpha M v - (h + beta) K v - C_air v),
//   v += dv, x += h v, with f = -grad(E_shell + gravity) and K the projected elastic Hessian at
//   x_n (prescribed vertices moved to their targets first, so a handle's motion enters through
//   f and K). Colliders are not a barrier here (one unguarded step would jump over it): a
//   vertex that ends within dhat of a collider is projected back to distance dhat and its
//   normal velocity towards the collider removed (our simplification of ARCSim's impact
//   zones).
// static_solve: equilibrium of E_shell + gravity + colliders by the same Newton method.
//
// Friction (sim/friction.hpp), where a collider has mu > 0: implicit_euler_step and static_solve
// add the lagged friction potential, with the normal forces and tangent bases taken at the
// step's start (statics: friction_start, the previous load step's equilibrium, else x as given)
// and P.friction_updates re-solves with them taken at the solution (IPC's lag update).
// baraff_witkin_step applies no friction: it has no barrier, hence no normal force to lag (its
// collider response is a projection).
#include "sim/newton.hpp"

#include <cmath>
#include <vector>

namespace yarnhom::sim {

// Moving obstacles (sim/obstacles.hpp) across a step: y their positions at the step's start
// (updated to where they end), target where their path puts them at its end. An obstacle that
// the cloth blocks (CCD leaves no safe move within `max_stages` solves) lags behind its path.
struct ObstacleMotion {
  Eigen::VectorXd y, target;
  double time = 0;  // s, the step's end (seams, gravity delay)
  int max_stages = 8;
  // The self-collision broad phase, carried from step to step (sim/contact_broad_phase.hpp: its
  // pairs' distance bounds carry over); made by the first step that needs it.
  std::shared_ptr<ContactCache> contact_cache;
};

struct StepStats {
  NewtonStats newton;          // Newton integrator / static solve
  int contact_stages = 0;      // solves of the step (more than one when a contact limited the start's move)
  bool finite = true;          // every position and velocity finite after the step
  int projected_vertices = 0;  // Baraff-Witkin step: collider projections
};

// x, v: 3n. target: 3n positions of the prescribed vertices at the end of the step (other
// entries ignored). hinges (optional): the dihedral angles at x on their continuous branch
// (sim/hinge_angles.hpp), updated to the step's end; without it each step starts from
// (-pi, pi] at x (still continuous within the step).
// potential_at_x (optional): the potential energy (shell, gravity, colliders; on the hinges'
// carried branches) at x, when the caller has it (the previous step's record): it spares one
// energy pass in choosing the start point.
StepStats implicit_euler_step(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                              Eigen::VectorXd& x, Eigen::VectorXd& v, const Eigen::VectorXd& target, double h,
                              const NewtonSettings& opt, bool profile = false, std::vector<double>* hinges = nullptr,
                              double potential_at_x = NAN, ObstacleMotion* obstacles = nullptr);

// opt: as for the Newton step; its max_iterations is ignored (one).
StepStats linearized_step(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                          Eigen::VectorXd& x, Eigen::VectorXd& v, const Eigen::VectorXd& target, double h,
                          const NewtonSettings& opt, bool profile = false, std::vector<double>* hinges = nullptr,
                          double potential_at_x = NAN, ObstacleMotion* obstacles = nullptr);

StepStats baraff_witkin_step(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                             Eigen::VectorXd& x, Eigen::VectorXd& v, const Eigen::VectorXd& target, double h,
                             bool profile = false, std::vector<double>* hinges = nullptr);

StepStats static_solve(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                       Eigen::VectorXd& x, const Eigen::VectorXd& target, const NewtonSettings& opt,
                       bool profile = false, std::vector<double>* hinges = nullptr,
                       const Eigen::VectorXd* friction_start = nullptr);

// Sets the prescribed vertices of x to target.
void apply_targets(const DofMap& D, const Eigen::VectorXd& target, Eigen::VectorXd& x);

}  // namespace yarnhom::sim
