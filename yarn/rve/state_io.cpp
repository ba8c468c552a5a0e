#include "yarn/rve/state_io.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/h5.hpp"
#include "io/obj_write.hpp"
#include "yarn/rod/certificate_io.hpp"
#include "yarn/rod/frames.hpp"

namespace yarnhom::yarn {

void write_state(const std::string& path, const RveProblem& rve, const Strain& s,
                 const RveState& st, const DensityResult& r) {
  const int n = rve.pattern().size();
  AtomicOutput out(path);
  {
    h5::Node root = h5::create_file(out.temp_path(), kStateFormat, 1);
    root.set_attr("pattern", rve.pattern().name);
    root.set_attr("units", "SI");
    root.set_attr("strain", std::vector<double>(s.data(), s.data() + 6));
    root.set_attr("psi", r.psi);
    root.set_attr("grad", std::vector<double>(r.grad.data(), r.grad.data() + 6));
    root.set_attr("energy", r.report.energy);
    root.set_attr("converged", r.report.converged() ? 1 : 0);
    root.set_attr("status", to_string(r.report.status));
    root.set_attr("iterations", r.report.iterations);
    root.set_attr("residual", r.report.residual);
    root.set_attr("seconds", r.report.seconds);
    root.set_attr("material", format_material(rve.material()));
    const Eigen::Matrix2d& F0 = rve.reference();
    root.set_attr("reference", std::vector<double>{F0(0, 0), F0(0, 1), F0(1, 0), F0(1, 1)});
    const Eigen::VectorXd q = st.packed();
    root.write("q", std::vector<double>(q.data(), q.data() + q.size()), {hsize_t(n), 4});
    std::vector<double> x, t, d1;
    for (const auto& p : rve.positions(s, st)) x.insert(x.end(), {p[0], p[1], p[2]});
    for (const auto& f : st.frames.edge) {
      t.insert(t.end(), {f.t[0], f.t[1], f.t[2]});
      d1.insert(d1.end(), {f.d1[0], f.d1[1], f.d1[2]});
    }
    root.write("positions", x, {hsize_t(n), 3});
    h5::Node fr = root.create_group("frames");
    fr.write("t", t, {hsize_t(n), 3});
    fr.write("d1", d1, {hsize_t(n), 3});
    fr.write("twist", st.frames.twist, {hsize_t(n)});
    // The topology certificate of the path that led here, and the path itself when recorded
    // (every configuration from the pattern's own geometry: re-checkable, yarnhom rve --certify).
    h5::Node cg = write_certificate(root, st.certificate);
    cg.set_attr("anchor_strain", std::vector<double>(st.anchor.s.data(), st.anchor.s.data() + 6));
    if (!st.path.empty()) {
      const hsize_t m = st.path.size();
      std::vector<double> ps, pu;
      for (const PathPoint& pp : st.path) {
        ps.insert(ps.end(), pp.s.data(), pp.s.data() + 6);
        for (const auto& u : pp.u) pu.insert(pu.end(), {u[0], u[1], u[2]});
      }
      cg.write("path_strain", ps, {m, 6});
      cg.write("path_u", pu, {m, hsize_t(n), 3});
    }
  }
  out.commit();
}

RveState read_state(const std::string& path, const RveProblem& rve) {
  const h5::Node root = h5::open_file(path);
  if (!root.has_attr("format") || root.attr_string("format") != kStateFormat)
    root.fail("/", std::string("not a yarnhom RVE state (attribute format != \"") + kStateFormat + "\")");
  const int n = rve.pattern().size();
  const auto q = root.read_double("q");
  if (q.dims.size() != 2 || int(q.rows()) != n || q.cols() != 4)
    root.fail("q", "expected shape [" + std::to_string(n) + ", 4] for pattern '" + rve.pattern().name + "'");
  RveState st = rve.initial_state();
  for (int v = 0; v < n; ++v) {
    st.u[v] = Eigen::Vector3d(q.data[4 * v], q.data[4 * v + 1], q.data[4 * v + 2]);
    st.theta[v] = q.data[4 * v + 3];
    if (!st.u[v].allFinite() || !std::isfinite(st.theta[v])) root.fail("q", "non-finite value at vertex " + std::to_string(v));
  }
  if (root.has("frames")) {
    const h5::Node fr = root.group("frames");
    const auto t = fr.read_double("t"), d1 = fr.read_double("d1"), tw = fr.read_double("twist");
    if (int(t.rows()) != n || int(d1.rows()) != n || int(tw.data.size()) != n)
      fr.fail("", "frame arrays do not have " + std::to_string(n) + " rows");
    for (int v = 0; v < n; ++v) {
      st.frames.edge[v] = {Eigen::Vector3d(t.data[3 * v], t.data[3 * v + 1], t.data[3 * v + 2]),
                           Eigen::Vector3d(d1.data[3 * v], d1.data[3 * v + 1], d1.data[3 * v + 2])};
      st.frames.twist[v] = tw.data[v];
    }
  }
  // The certificate as the file states it, and the configuration it ends at; a file without
  // one (written before certificates existed) is not certified.
  st.anchor = {Strain::Zero(), st.u};
  if (root.has_attr("strain")) {
    const auto sv = root.attr_doubles("strain");
    if (sv.size() == 6) st.anchor.s = Eigen::Map<const Strain>(sv.data());
  }
  const ContactCertificate c = read_certificate(root, rve.min_separation(), "the state file has no topology certificate");
  if (root.has("certificate")) {
    const h5::Node cg = root.group("certificate");
    if (cg.has_attr("anchor_strain")) {
      const auto sv = cg.attr_doubles("anchor_strain");
      if (sv.size() == 6) st.anchor.s = Eigen::Map<const Strain>(sv.data());
    }
    if (cg.has("path_strain")) {
      const auto ps = cg.read_double("path_strain"), pu = cg.read_double("path_u");
      const size_t m = ps.rows();
      if (ps.cols() != 6 || pu.dims.size() != 3 || pu.dims[0] != m || int(pu.dims[1]) != n || pu.dims[2] != 3)
        cg.fail("path_u", "path arrays do not match (expected [m, 6] and [m, " + std::to_string(n) + ", 3])");
      st.path.resize(m);
      for (size_t i = 0; i < m; ++i) {
        st.path[i].s = Eigen::Map<const Strain>(&ps.data[6 * i]);
        st.path[i].u.resize(n);
        for (int v = 0; v < n; ++v) st.path[i].u[v] = Eigen::Map<const Eigen::Vector3d>(&pu.data[(i * n + v) * 3]);
      }
    }
  }
  st.certificate = c;
  return st;
}

Eigen::Matrix2d read_state_reference(const std::string& path) {
  const h5::Node root = h5::open_file(path);
  if (!root.has_attr("format") || root.attr_string("format") != kStateFormat)
    root.fail("/", std::string("not a yarnhom RVE state (attribute format != \"") + kStateFormat + "\")");
  Eigen::Matrix2d F0 = Eigen::Matrix2d::Identity();
  if (!root.has_attr("reference")) return F0;
  const std::vector<double> r = root.attr_doubles("reference");
  if (r.size() != 4) root.fail("/", "attribute reference must have 4 entries (F0 row-major)");
  F0 << r[0], r[1], r[2], r[3];
  if (!F0.allFinite() || r[2] != 0.0 || !(r[0] > 0 && r[3] > 0))
    root.fail("/", "attribute reference is not upper triangular with a positive diagonal");
  return F0;
}

void write_obj(const std::string& path, const RveProblem& rve, const Strain& s,
               const RveState& st, int sides) {
  const Topology& topo = rve.topo();
  const double r = rve.radius();
  ObjWriter f(path);
  f.comment("yarnhom rve: pattern " + rve.pattern().name + ", one tube per yarn over one period");
  long next_index = 1;
  for (size_t y = 0; y < topo.yarns.size(); ++y) {
    // The yarn's centreline through the images, closed on the first vertex's image.
    std::vector<Eigen::Vector3d> c;
    Eigen::Vector2i o = Eigen::Vector2i::Zero();
    for (int v : topo.yarns[y]) {
      c.push_back(rve.position(s, st, v, o));
      o += topo.offset[v];
    }
    c.push_back(rve.position(s, st, topo.yarns[y][0], o));
    const int m = static_cast<int>(c.size());
    f.object("yarn" + std::to_string(y));
    // Ring frames by parallel transport along the centreline: no twisting of the mesh.
    Eigen::Vector3d t0 = (c[1] - c[0]).normalized();
    Eigen::Vector3d a = std::abs(t0[2]) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    Eigen::Vector3d d = (a - a.dot(t0) * t0).normalized();
    Eigen::Vector3d tprev = t0;
    for (int k = 0; k < m; ++k) {
      const Eigen::Vector3d t = k == 0 ? t0 : k + 1 < m ? (c[k + 1] - c[k - 1]).normalized() : (c[k] - c[k - 1]).normalized();
      const V3<double> dd = transport_same(V3<double>(tprev), V3<double>(t), V3<double>(d));
      d = Eigen::Vector3d(dd.x, dd.y, dd.z);
      d = (d - d.dot(t) * t).normalized();
      tprev = t;
      const Eigen::Vector3d e = t.cross(d);
      for (int j = 0; j < sides; ++j) {
        const double phi = 2 * M_PI * j / sides;
        const Eigen::Vector3d p = c[k] + r * (std::cos(phi) * d + std::sin(phi) * e);
        f.vertex(p[0], p[1], p[2]);
      }
    }
    for (int k = 0; k + 1 < m; ++k)
      for (int j = 0; j < sides; ++j) {
        const long a0 = next_index + k * sides + j, a1 = next_index + k * sides + (j + 1) % sides;
        f.face({a0, a1, a1 + sides, a0 + sides});
      }
    next_index += long(m) * sides;
  }
  f.commit();
}

}  // namespace yarnhom::yarn
