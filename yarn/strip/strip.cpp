#include "yarn/strip/strip.hpp"

#include <cmath>
#include <stdexcept>

#include "yarn/rod/rod.hpp"

namespace yarnhom::yarn {

const char* to_string(StripAxis a) { return a == StripAxis::kCourse ? "course" : "wale"; }

void set_rest_to_shape(Strip& s, bool all) {
  const int n = s.size(), ne = s.num_edges();
  std::vector<Eigen::Vector3d> tan(ne);
  for (int e = 0; e < ne; ++e) {
    tan[e] = (s.x[s.next(e)] - s.x[e]).normalized();
    if (all || s.connector_edge[e]) s.rest_length[e] = (s.x[s.next(e)] - s.x[e]).norm();
  }
  for (int v = 0; v < n; ++v) {
    if (!s.has_joint(v) || !(all || s.connector_joint[v])) continue;
    const int a = s.prev(v), b = s.next(v);
    Vec11 q;
    q << s.x[a], s.x[v], s.x[b], s.theta[a], s.theta[v];
    const JointFrames f{{tan[a], s.ref_d1[a]}, {tan[v], s.ref_d1[v]}, s.ref_twist[v]};
    const JointStrain js = joint_strain(q, f);
    s.rest_kappa[v] = Eigen::Vector2d(js.k1, js.k2);
    s.rest_twist[v] = js.twist;
  }
}

void check_strip(const Strip& s) {
  const int n = s.size(), ne = s.num_edges();
  auto fail = [&](const std::string& what) { throw std::invalid_argument("strip '" + s.name + "': " + what); };
  if (n < 3) fail("fewer than 3 vertices");
  if (!(s.radius > 0)) fail("radius must be positive");
  if (static_cast<int>(s.source.size()) != n) fail("source: one per vertex expected");
  if (static_cast<int>(s.theta.size()) != ne || static_cast<int>(s.rest_length.size()) != ne ||
      static_cast<int>(s.ref_d1.size()) != ne || static_cast<int>(s.connector_edge.size()) != ne)
    fail("per-edge arrays: " + std::to_string(ne) + " entries expected");
  if (static_cast<int>(s.rest_kappa.size()) != n || static_cast<int>(s.rest_twist.size()) != n ||
      static_cast<int>(s.ref_twist.size()) != n || static_cast<int>(s.connector_joint.size()) != n)
    fail("per-joint arrays: " + std::to_string(n) + " entries expected");
  for (int e = 0; e < ne; ++e) {
    const Eigen::Vector3d d = s.x[s.next(e)] - s.x[e];
    if (!(d.norm() > 0)) fail("edge " + std::to_string(e) + " has zero length");
    if (!(s.rest_length[e] > 0)) fail("edge " + std::to_string(e) + " has a non-positive rest length");
    if (std::abs(s.ref_d1[e].norm() - 1) > 1e-9 || std::abs(s.ref_d1[e].dot(d.normalized())) > 1e-9)
      fail("edge " + std::to_string(e) + ": reference director not a unit vector perpendicular to the edge");
  }
}

}  // namespace yarnhom::yarn
