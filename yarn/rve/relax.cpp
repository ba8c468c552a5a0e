#include "yarn/rve/relax.hpp"

#include <stdexcept>

#include "yarn/rod/rod.hpp"

namespace yarnhom::yarn {

Pattern pattern_at(const RveProblem& rve, const RveState& st) {
  Pattern q = rve.pattern();
  // The reference tile becomes the pattern's tile (a .pyp tile is a rectangle).
  if (rve.reference()(0, 1) != 0.0)
    throw std::invalid_argument("pattern '" + q.name + "': a sheared reference tile cannot be written as a .pyp");
  q.px = rve.lattice()(0, 0);
  q.py = rve.lattice()(1, 1);
  const Strain zero = Strain::Zero();
  q.x = rve.positions(zero, st);
  q.theta = st.theta;
  const Topology& t = rve.topo();
  const int n = q.size();
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d tan = stored_edge(q, t, v).normalized();
    q.ref_d1[v] = transported_director(st.frames.edge[v], tan);
  }
  for (int v = 0; v < n; ++v) {
    const int a = t.prev[v];
    q.ref_twist[v] = reference_twist(stored_edge(q, t, a).normalized(), q.ref_d1[a],
                                     stored_edge(q, t, v).normalized(), q.ref_d1[v], st.frames.twist[v]);
  }
  return q;
}

Pattern relax_pattern(const Pattern& p, const Material& m, SolveReport* report, const SolveOptions& opt) {
  const RveProblem rve(p, m);
  RveState st = rve.initial_state();
  const SolveReport rep = solve(rve, Strain::Zero(), st, opt);
  if (report) *report = rep;
  if (!rep.converged())
    throw std::runtime_error("relaxing pattern '" + p.name + "' at rest failed: " + rep.summary());
  return pattern_at(rve, st);
}

}  // namespace yarnhom::yarn
