// The energy of an RVE configuration per vertex (energy_map.hpp).
#include "yarn/rve/energy_map.hpp"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "numerics/barrier.hpp"
#include "yarn/rod/contact.hpp"
#include "yarn/rod/rod.hpp"

namespace yarnhom::yarn {

std::vector<VertexEnergy> energy_map(const RveProblem& rve, const Strain& s, const RveState& st) {
  const Pattern& p = rve.pattern();
  const Topology& t = rve.topo();
  const Material& m = rve.material();
  const double r = p.radius;
  const double EA = rve.stretch_stiffness(), EI = m.young * M_PI * r * r * r * r / 4,
               GJ = m.shear * M_PI * r * r * r * r / 2;
  const int n = p.size();
  std::vector<VertexEnergy> out(n);
  const auto X = [&](int v, Eigen::Vector2i o) { return rve.position(s, st, v, o); };
  for (int v = 0; v < n; ++v) {
    const int a = t.prev[v], b = t.next[v];
    VertexEnergy& ve = out[v];
    ve.yarn = t.yarn_of[v];
    ve.x = X(v, {0, 0});
    ve.pattern_x = p.x[v];
    const Eigen::Vector3d xb = X(b, t.offset[v]), xa = X(a, -t.offset[a]);
    ve.e.stretch = stretch_energy(ve.x, xb, p.rest_length[v], EA, nullptr, nullptr);
    Vec11 q;
    q << xa, ve.x, xb, st.theta[a], st.theta[v];
    // The stored frames turned by the joint's local mid-surface frame, as the RVE's joints do (rve.cpp).
    const ShellPoint<double> sp = rve.shell_point(s, v, {0, 0});
    Eigen::Matrix3d R;
    for (int c = 0; c < 3; ++c) R.col(c) = Eigen::Vector3d(sp.R[c].x, sp.R[c].y, sp.R[c].z);
    const JointFrames f{{R * st.frames.edge[a].t, R * st.frames.edge[a].d1},
                        {R * st.frames.edge[v].t, R * st.frames.edge[v].d1},
                        st.frames.twist[v]};
    const JointRest rest{p.rest_kappa[v], p.rest_twist[v], 0.5 * (p.rest_length[a] + p.rest_length[v])};
    ve.e.bend = joint_energy(q, f, rest, EI, GJ, kBend, nullptr, nullptr);
    ve.e.twist = joint_energy(q, f, rest, EI, GJ, kTwist, nullptr, nullptr);
    const JointStrain js = joint_strain(q, f);
    ve.curvature = std::hypot(js.k1, js.k2) / rest.voronoi;
    ve.rest_curvature = p.rest_kappa[v].norm() / rest.voronoi;
  }
  const ContactParams cp{r, m.contact_stiffness * r, rve.options().contact_quadrature};
  for (const RveProblem::Pair& pr : rve.contact_pairs(s, st, 0.0)) {
    if (rve.excluded(pr.a, pr.b, pr.o)) continue;
    Vec12 q;
    q << X(pr.a, {0, 0}), X(t.next[pr.a], t.offset[pr.a]), X(pr.b, pr.o), X(t.next[pr.b], pr.o + t.offset[pr.b]);
    const double ec = segment_contact_energy(q, p.rest_length[pr.a], p.rest_length[pr.b], cp, nullptr, nullptr);
    const double eb = numerics::segment_barrier_energy(q, rve.barrier());
    out[pr.a].e.contact += ec / 2, out[pr.b].e.contact += ec / 2;
    out[pr.a].e.barrier += eb / 2, out[pr.b].e.barrier += eb / 2;
  }
  return out;
}

void write_energy_map(const std::string& path, const RveProblem& rve, const std::vector<VertexEnergy>& map) {
  const double r = rve.radius(), A = rve.area();
  const std::string tmp = path + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot write the energy map");
  std::fprintf(f, "# %s: energy per vertex, J/m^2 of the reference tile (%.6g m^2); lengths in yarn radii (%.6g m)\n",
               display_name(rve.pattern()).c_str(), A, r);
  std::fprintf(f, "vertex\tyarn\tx\ty\tz\tx_pattern\ty_pattern\tz_pattern\tstretch\tbend\ttwist\tcontact\tbarrier\t"
                  "curvature\trest_curvature\n");
  for (const auto& yarn : rve.topo().yarns)
    for (int v : yarn) {
      const VertexEnergy& e = map[v];
      std::fprintf(f, "%d\t%d\t%.6g\t%.6g\t%.6g\t%.6g\t%.6g\t%.6g\t%.6e\t%.6e\t%.6e\t%.6e\t%.6e\t%.6g\t%.6g\n", v, e.yarn,
                   e.x[0] / r, e.x[1] / r, e.x[2] / r, e.pattern_x[0] / r, e.pattern_x[1] / r, e.pattern_x[2] / r,
                   e.e.stretch / A, e.e.bend / A, e.e.twist / A, e.e.contact / A, e.e.barrier / A, e.curvature * r,
                   e.rest_curvature * r);
    }
  const bool ok = std::fclose(f) == 0;
  if (!ok) throw std::runtime_error(path + ": writing the energy map failed");
  std::filesystem::rename(tmp, path);
}

}  // namespace yarnhom::yarn
