#include "yarn/strip/strip_io.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/h5.hpp"
#include "io/obj_read.hpp"
#include "io/obj_write.hpp"
#include "yarn/rod/certificate_io.hpp"

namespace yarnhom::yarn {

void write_centrelines(const std::string& path, const Strip& s, const std::vector<Eigen::Vector3d>& x) {
  ObjWriter w(path);
  w.comment("yarnhom strip " + s.name + ": " + std::to_string(s.size()) + " vertices, one yarn (m)");
  for (const auto& p : x) w.vertex(p[0], p[1], p[2]);
  // Runs of edges of one kind.
  const int ne = s.num_edges();
  for (int a = 0; a < ne;) {
    int b = a;
    while (b < ne && s.connector_edge[b] == s.connector_edge[a]) ++b;
    w.group(s.connector_edge[a] ? "boundary" : "yarn");
    std::vector<long> line;
    for (int v = a; v <= b; ++v) line.push_back((v == s.size() ? 0 : v) + 1);
    w.polyline(line);
    a = b;
  }
  w.commit();
}

Polylines read_polylines(const std::string& path) {
  const ObjGeometry g = read_obj_geometry(path);
  Polylines P;
  for (Eigen::Index i = 0; i < g.V.cols(); ++i) P.v.push_back(g.V.col(i));
  P.lines = g.lines;
  return P;
}

void write_step(const std::string& path, const Strip& s, const StretchStep& r, const StripState& st) {
  const int n = s.size(), ne = s.num_edges();
  AtomicOutput out(path);
  {
    h5::Node root = h5::create_file(out.temp_path(), kStripStepFormat, 1);
    root.set_attr("units", "SI");
    root.set_attr("strip", s.name);
    root.set_attr("stretch", r.stretch);
    root.set_attr("force_low", r.force_low);
    root.set_attr("force_high", r.force_high);
    root.set_attr("force", r.force);
    root.set_attr("tension", r.tension);
    root.set_attr("energy", r.energy);
    root.set_attr("min_distance", r.min_distance);
    root.set_attr("status", to_string(r.solve.status));
    root.set_attr("iterations", r.solve.iterations);
    root.set_attr("residual", r.solve.residual);
    root.set_attr("seconds", r.solve.seconds);
    root.set_attr("assembly_seconds", r.solve.assembly_seconds);
    root.set_attr("factor_seconds", r.solve.factor_seconds);
    root.set_attr("line_search_seconds", r.solve.line_search_seconds);
    std::vector<double> x, t, d1;
    for (const auto& p : st.x) x.insert(x.end(), {p[0], p[1], p[2]});
    for (const auto& f : st.frames) {
      t.insert(t.end(), {f.t[0], f.t[1], f.t[2]});
      d1.insert(d1.end(), {f.d1[0], f.d1[1], f.d1[2]});
    }
    root.write("x", x, {hsize_t(n), 3});
    root.write("theta", st.theta, {hsize_t(ne)});
    h5::Node fr = root.create_group("frames");
    fr.write("t", t, {hsize_t(ne), 3});
    fr.write("d1", d1, {hsize_t(ne), 3});
    fr.write("twist", st.twist, {hsize_t(n)});
    // The topology certificate of every move from the generated strip to here (a resumed run
    // carries it on).
    write_certificate(root, st.certificate);
  }
  out.commit();
}

StretchStep read_step(const std::string& path, const StripProblem& P, StripState& st) {
  const h5::Node root = h5::open_file(path);
  if (!root.has_attr("format") || root.attr_string("format") != kStripStepFormat)
    root.fail("/", std::string("not a yarnhom strip step (attribute format != \"") + kStripStepFormat + "\")");
  const int n = P.strip().size(), ne = P.strip().num_edges();
  auto shape = [&](const h5::Array<double>& a, int rows, int cols, const char* name) {
    const bool ok = cols == 1 ? (a.dims.size() == 1 && int(a.rows()) == rows)
                              : (a.dims.size() == 2 && int(a.rows()) == rows && int(a.cols()) == cols);
    if (!ok)
      root.fail(name, "shape does not match strip '" + P.strip().name + "' (" + std::to_string(rows) + " x " +
                          std::to_string(cols) + " expected)");
  };
  const auto x = root.read_double("x");
  shape(x, n, 3, "x");
  const auto th = root.read_double("theta");
  shape(th, ne, 1, "theta");
  const h5::Node fr = root.group("frames");
  const auto t = fr.read_double("t"), d1 = fr.read_double("d1"), tw = fr.read_double("twist");
  shape(t, ne, 3, "frames/t");
  shape(d1, ne, 3, "frames/d1");
  shape(tw, n, 1, "frames/twist");
  st = P.initial_state();
  for (int v = 0; v < n; ++v) st.x[v] = Eigen::Vector3d(x.data[3 * v], x.data[3 * v + 1], x.data[3 * v + 2]);
  st.theta = th.data;
  for (int e = 0; e < ne; ++e)
    st.frames[e] = {Eigen::Vector3d(t.data[3 * e], t.data[3 * e + 1], t.data[3 * e + 2]),
                    Eigen::Vector3d(d1.data[3 * e], d1.data[3 * e + 1], d1.data[3 * e + 2])};
  st.twist = tw.data;
  // A file without a certificate certifies nothing.
  st.certificate = read_certificate(root, P.contact().dmin(), "the step file has no topology certificate");
  const ContactCertificate& c = st.certificate;
  StretchStep r;
  r.stretch = root.attr_double("stretch");
  r.force_low = root.attr_double("force_low");
  r.force_high = root.attr_double("force_high");
  r.force = root.attr_double("force");
  r.tension = root.attr_double("tension");
  r.energy = root.attr_double("energy");
  r.min_distance = root.attr_double("min_distance");
  const std::string status = root.attr_string("status");
  r.solve.status = status == "converged" ? SolveStatus::kConverged
                   : status == "line_search_failed" ? SolveStatus::kLineSearchFailed
                   : status == "non_finite" ? SolveStatus::kNonFinite
                                            : SolveStatus::kMaxIterations;
  r.solve.iterations = static_cast<int>(root.attr_int("iterations"));
  r.solve.residual = root.attr_double("residual");
  r.solve.seconds = root.attr_double("seconds");
  r.solve.assembly_seconds = root.attr_double("assembly_seconds");
  r.solve.factor_seconds = root.attr_double("factor_seconds");
  r.solve.line_search_seconds = root.attr_double("line_search_seconds");
  r.certificate = c;
  return r;
}

}  // namespace yarnhom::yarn
