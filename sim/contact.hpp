#pragma once
// Surface contact of the cloth with itself and with the obstacles of sim/obstacles.hpp
// (capsules, triangle meshes): IPC (Li et al. 2020) on point-triangle and edge-edge pairs, with
// the numerics of numerics/contact_distance.hpp and numerics/contact_pairs.hpp.
//
// Pairs (a pair's four slots are cloth vertices, >= 0, or obstacle points, -1 - k):
//   self:      cloth vertex - cloth triangle, cloth edge - cloth edge, sharing no vertex;
//   meshes:    cloth vertex - obstacle triangle, obstacle vertex - cloth triangle, cloth edge -
//              obstacle edge;
//   capsules:  cloth edge - capsule axis, capsule end - cloth triangle, at d_min = the radius
//              (the closest points of a triangle and a segment are one of those features).
// Energy of a pair: kappa_J b(z), z = (D - d_min^2) / ((d_min + dhat)^2 - d_min^2), D the squared
// distance, b IPC's log barrier, kappa_J = kappa A dhat with kappa the colliders' barrier
// stiffness (Pa) and A the mean lumped area of the pair's cloth vertices: the colliders' scale.
// Its 12 x 12 Hessian is projected onto the PSD cone before assembly; the couplings between
// vertices that the mesh does not connect come back as triplets (the Newton matrix's pattern
// then grows by them: sim/newton.cpp).
//
// Candidates come from a spatial hash over boxes (numerics/contact_pairs.hpp: box_pairs) inflated
// so that two boxes overlap whenever their primitives may be within d_min + dhat: every energy
// evaluation finds its own pairs at its own positions, every CCD its pairs over the swept boxes
// of its move (sim/contact_broad_phase.hpp), either from a fresh hash or, given a ContactCache,
// as the same pair set from a hash over a region that covers the positions (one per step's
// stage of the simulator; the functions below take it as their last, optional argument).
//
// Friction between cloth layers and with obstacles: IPC's lagged friction (sim/friction.hpp's
// mollifier) on the pair's relative tangential slip u = T^T sum_k w_k (q_k - q_k^start), w the
// closest points' weights (numerics: contact_weights), T a basis of the plane normal to the
// closest points' difference, lambda the barrier's normal force, all at the step's start.
#include <Eigen/Sparse>
#include <array>
#include <vector>

#include "numerics/barrier.hpp"
#include "numerics/contact_distance.hpp"
#include "sim/contact_broad_phase.hpp"
#include "sim/problem.hpp"

namespace yarnhom::sim {


// Unique cloth edges (a < b).
std::vector<Eigen::Vector2i> cloth_edges(const Mesh& mesh);

// True when P has anything for contact pairs (self-collision on, or obstacles).
bool has_contact(const Problem& P);

// A pair's 12 coordinates.
numerics::Vec12 pair_coordinates(const ContactPair& c, const Eigen::VectorXd& x, const Eigen::VectorXd& y);

// The pair's barrier parameters (d_min, d_min + dhat, kappa_J).
numerics::BarrierParams pair_barrier(const Problem& P, const ContactPair& c);

// The barrier energy of every pair at (x, y). grad (3n): gradient added at cloth vertices.
// triplets: the projected Hessian's lower triangle over free unknowns (3 per free vertex, the
// free_index of the DofMap). Returns +inf when a pair is at or below d_min. The pairs' terms
// are evaluated on the OpenMP threads and summed in the pairs' order (the same on any thread
// count; pair_friction_energy likewise).
double contact_energy(const Problem& P, const std::vector<int>& free_index, const Eigen::VectorXd& x,
                      const Eigen::VectorXd& y, Eigen::VectorXd* grad = nullptr,
                      std::vector<Eigen::Triplet<double>>* triplets = nullptr, ContactCache* cache = nullptr);

// The largest fraction of the move (x0 -> x0 + t dx, y0 -> y0 + t dy) on which no pair comes closer
// than d_min + eta (d(0) - d_min) (numerics: contact_ccd); 1 when the whole move is safe. A pair
// whose obstacle points move comes no closer than d_min + dhat / 10 either (from within it,
// only moves that shrink its distance by at most kFloorCreep = 1e-3 of its gap, sampled along
// the move: a vertex carried along keeps its distance up to the obstacle's rounding), so that
// an obstacle pressing cloth against something fixed stops instead of closing the gap to
// rounding.
// hits (optional): the cloth vertices of the pairs that limit it (t < 1), with, for a pair with
// an obstacle, the mean displacement of its obstacle points over the move.
struct ContactHit {
  int vertex = 0;
  bool obstacle = false;
  Eigen::Vector3d carry = Eigen::Vector3d::Zero();
  double gap = 0;  // the pair's distance less d_min at the move's start
  std::array<int, 4> slot{-1, -1, -1, -1};  // the pair's slots (ContactPair::slot)
};
double contact_step_bound(const Problem& P, const Eigen::VectorXd& x0, const Eigen::VectorXd& dx,
                          const Eigen::VectorXd& y0, const Eigen::VectorXd& dy, std::vector<ContactHit>* hits = nullptr,
                          ContactCache* cache = nullptr);

// Makes the move (x0 -> x1, y0 -> y1) safe for contact where it can, by changing x1: a cloth
// vertex of a limiting pair with an obstacle is carried by the obstacle's displacement (it moves
// with the obstacle instead of being passed through); one of a limiting self pair is carried
// by the carry of the pair's carried vertex, if it has one (pushed along: the next layer of
// cloth ahead of a moving body), else stays at x0; prescribed vertices (free_index < 0) keep
// their move. A carry that would cross a collider (P.colliders), or that leaves the vertex
// limiting in the next round against an obstacle whose move differs from the carry by more
// than a tenth of the pair's gap (it was carried into another one: pinched), is undone for
// good: the vertex stays at x0 and so holds the carrying obstacle back (still limiting against
// an obstacle that moves as it was carried is no pinch: the pair's other cloth vertices are
// carried in that round). Repeats while that changes something
// (at most `rounds` times). Returns the safe fraction of the final move (1: all of it).
double make_move_safe(const Problem& P, const std::vector<int>& free_index, const Eigen::VectorXd& x0,
                      Eigen::VectorXd& x1, const Eigen::VectorXd& y0, const Eigen::VectorXd& y1, int rounds = 6,
                      ContactCache* cache = nullptr);

// Lagged friction of one pair.
struct PairFriction {
  ContactPair pair;
  Eigen::Vector4d w = Eigen::Vector4d::Zero();
  Eigen::Matrix<double, 3, 2> T = Eigen::Matrix<double, 3, 2>::Zero();
  double mu_lambda = 0;
  numerics::Vec12 q_start = numerics::Vec12::Zero();
};

// Pairs with mu > 0 within their activation distance at (x_at, y_at); slip measured from
// (x_start, y_start).
std::vector<PairFriction> pair_friction_contacts(const Problem& P, const Eigen::VectorXd& x_at, const Eigen::VectorXd& y_at,
                                                 const Eigen::VectorXd& x_start, const Eigen::VectorXd& y_start,
                                                 ContactCache* cache = nullptr);

// The friction potential of the lagged pairs at (x, y), with gradient and Hessian triplets as
// contact_energy. majorize: the Hessian's 2 x 2 slip block is (f1(y)/y) I, the curvature of the
// quadratic that touches f0(|u|) at u and lies above it everywhere (f1(y)/y does not increase),
// instead of the exact (f1(y)/y) I + (f1' - f1/y) u u^T / y^2, whose stiffness along a sliding
// slip is f1' = 0: a Newton step then moves a sliding vertex by its friction force over the
// mass term alone (the one-solve step's moving body: 30 cm on a 1.7 cm step, sim/integrators.hpp),
// where the majorizer's step brings it at most to sticking. Value and gradient are the same.
double pair_friction_energy(const std::vector<PairFriction>& F, double eps, const std::vector<int>& free_index,
                            const Eigen::VectorXd& x, const Eigen::VectorXd& y, Eigen::VectorXd* grad = nullptr,
                            std::vector<Eigen::Triplet<double>>* triplets = nullptr, bool majorize = false);

// True when some non-adjacent cloth triangles intersect, or a cloth triangle meets an obstacle
// (a mesh triangle, or comes within a capsule's radius of its axis): the exact check of
// numerics::triangles_intersect. what (optional): the first offending pair in words.
bool contact_intersections(const Problem& P, const Eigen::VectorXd& x, const Eigen::VectorXd& y,
                           std::string* what = nullptr);

}  // namespace yarnhom::sim
