#pragma once
// Helpers of the sim tests: per-triangle strain of a whole mesh at given positions.
#include <vector>

#include "sim/element_rest.hpp"
#include "sim/mesh.hpp"
#include "sim/shell_strain.hpp"

namespace yarnhom::test {

inline sim::Vec18 gather_element(const sim::Mesh& m, const Eigen::MatrixX3d& x, int t, bool has_flap[3]) {
  sim::Vec18 q = sim::Vec18::Zero();
  for (int i = 0; i < 3; ++i) {
    q.segment<3>(3 * i) = x.row(m.tris(t, i)).transpose();
    has_flap[i] = m.flaps(t, i) >= 0;
    if (has_flap[i]) q.segment<3>(9 + 3 * i) = x.row(m.flaps(t, i)).transpose();
  }
  return q;
}

inline std::vector<Strain6> mesh_strains(const sim::Mesh& m, const Eigen::MatrixX3d& x) {
  std::vector<Strain6> out(m.num_triangles());
  for (int t = 0; t < m.num_triangles(); ++t) {
    const sim::ElementRest r = sim::element_rest(m.rest.row(m.tris(t, 0)), m.rest.row(m.tris(t, 1)),
                                                 m.rest.row(m.tris(t, 2)));
    bool fl[3];
    const sim::Vec18 q = gather_element(m, x, t, fl);
    out[t] = sim::shell_strain(q, r, fl);
  }
  return out;
}

inline bool is_interior(const sim::Mesh& m, int t) {
  return m.flaps(t, 0) >= 0 && m.flaps(t, 1) >= 0 && m.flaps(t, 2) >= 0;
}

}  // namespace yarnhom::test
