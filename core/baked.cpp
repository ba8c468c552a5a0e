#include "core/baked.hpp"

#include <cmath>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/h5.hpp"
#include "core/term_attrs.hpp"

namespace yarnhom {

const BakedTable* BakedModel::find(const std::string& name) const { return find_term(tables, name); }

namespace {

void check_finite(const double* v, size_t n, const std::string& file, const std::string& obj) {
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i]))
      throw FileError(file, obj, "non-finite value at flat index " + std::to_string(i));
}

void check_size(const std::vector<double>& v, size_t n, const std::string& file,
                const std::string& obj) {
  if (v.size() != n)
    throw FileError(file, obj, "wrong size " + std::to_string(v.size()) + ", expected " +
                                   std::to_string(n));
  check_finite(v.data(), v.size(), file, obj);
}

}  // namespace

void validate_baked(const BakedModel& m, const std::string& file) {
  if (m.tables.empty()) throw FileError(file, "/tables", "no tables");
  if (!std::isfinite(m.psi0)) throw FileError(file, "/", "psi0 is not finite");
  if (!std::isnan(m.areal_density) && !(m.areal_density > 0 && std::isfinite(m.areal_density)))
    throw FileError(file, "/", "areal_density must be positive and finite (absent when unknown)");
  for (const BakedTable& t : m.tables) {
    const std::string g = "/tables/" + t.term.name;
    const size_t d = t.dim();
    if (t.extrapolation != kBakedSafeguard && t.extrapolation != kBakedLinear)
      throw FileError(file, g, "attribute extrapolation must be 'safeguard' or 'linear', not '" +
                                   t.extrapolation + "'");
    if (t.lower.size() != d || t.upper.size() != d || t.knots.size() != d)
      throw FileError(file, g, "attributes lower/upper/knots must have " + std::to_string(d) +
                                   " entries");
    for (size_t k = 0; k < d; ++k) {
      if (!(t.lower[k] < t.upper[k]) || !std::isfinite(t.lower[k]) || !std::isfinite(t.upper[k]))
        throw FileError(file, g, "empty or non-finite box: lower must be below upper");
      if (t.knots[k] < 2) throw FileError(file, g, "fewer than 2 knots on an axis");
    }
    const size_t n = t.num_knots();
    check_size(t.f, n, file, g + "/f");
    check_size(t.f_x, n, file, g + "/f_x");
    if (d == 1) {
      check_finite(t.safeguard_lower.data(), 3, file, g + " attribute safeguard_lower");
      check_finite(t.safeguard_upper.data(), 3, file, g + " attribute safeguard_upper");
    } else {
      check_size(t.f_y, n, file, g + "/f_y");
      check_size(t.f_xy, n, file, g + "/f_xy");
      for (int e = 0; e < 4; ++e)
        check_size(t.edges[e], size_t(t.knots[e < 2 ? 1 : 0]) * 6, file,
                   g + "/safeguard/" + kBakedEdgeNames[e]);
      for (int c = 0; c < 4; ++c)
        check_finite(t.corners[c].data(), 8, file, g + "/safeguard/" + kBakedCornerNames[c]);
    }
  }
}

void write_baked(const std::string& path, const BakedModel& m) {
  validate_baked(m, path);
  AtomicOutput out(path);
  {
    h5::Node root = h5::create_file(out.temp_path(), kBakedFormat, kBakedVersion);
    root.set_attr("model", m.model);
    root.set_attr("dataset", m.dataset);
    root.set_attr("psi0", m.psi0);
    root.set_attr("psi0_known", m.psi0_known ? 1 : 0);
    if (!std::isnan(m.areal_density)) root.set_attr("areal_density", m.areal_density);
    h5::Node tables = root.create_group("tables");
    for (const BakedTable& t : m.tables) {
      h5::Node g = tables.create_group(t.term.name);
      write_box_attrs(g, t.term, t.lower, t.upper);
      g.set_attr("knots", t.knots);
      write_network_attrs(g, t.desc, t.norm);
      g.set_attr("epochs", t.epochs);
      g.set_attr("backend", t.backend);
      g.set_attr("status", t.status);
      g.set_attr("extrapolation", t.extrapolation);
      std::vector<hsize_t> dims;
      for (int k : t.knots) dims.push_back(hsize_t(k));
      g.write("f", t.f, dims);
      g.write("f_x", t.f_x, dims);
      if (t.dim() == 1) {
        g.set_attr("safeguard_lower", std::vector<double>(t.safeguard_lower.begin(), t.safeguard_lower.end()));
        g.set_attr("safeguard_upper", std::vector<double>(t.safeguard_upper.begin(), t.safeguard_upper.end()));
      } else {
        g.write("f_y", t.f_y, dims);
        g.write("f_xy", t.f_xy, dims);
        h5::Node s = g.create_group("safeguard");
        for (int e = 0; e < 4; ++e)
          s.write(kBakedEdgeNames[e], t.edges[e], {hsize_t(t.knots[e < 2 ? 1 : 0]), 6});
        for (int c = 0; c < 4; ++c)
          s.write(kBakedCornerNames[c], std::vector<double>(t.corners[c].begin(), t.corners[c].end()), {8});
      }
    }
  }
  out.commit();
}

bool is_baked_file(const std::string& path) {
  h5::Node root = h5::open_file(path);
  return root.has_attr("format") && root.attr_string("format") == kBakedFormat;
}

BakedModel read_baked(const std::string& path) {
  h5::Node root = h5::open_file(path);
  if (!root.has_attr("format") || root.attr_string("format") != kBakedFormat)
    root.fail("/", std::string("not a yarnhom baked file (attribute format must be '") +
                       kBakedFormat + "')");
  if (root.attr_int("version") != kBakedVersion)
    root.fail("/", "unsupported baked-file version " + std::to_string(root.attr_int("version")));
  BakedModel m;
  m.model = root.attr_string("model");
  m.dataset = root.attr_string("dataset");
  m.psi0 = root.attr_double("psi0");
  m.psi0_known = root.attr_int("psi0_known") != 0;
  if (root.has_attr("areal_density")) m.areal_density = root.attr_double("areal_density");
  h5::Node tables = root.group("tables");
  for (const std::string& name : tables.children()) {
    const Term* term = nullptr;
    for (const Term& t : all_terms())
      if (t.name == name) term = &t;
    if (!term) tables.fail("/tables/" + name, "unknown term name");
  }
  for (const Term& term : all_terms()) {
    if (!tables.has(term.name)) continue;
    h5::Node g = tables.group(term.name);
    BakedTable t;
    t.term = term;
    if (g.attr_ints("indices") != term.indices)
      g.fail(g.path(), "attribute indices does not match the term name");
    t.lower = g.attr_doubles("lower");
    t.upper = g.attr_doubles("upper");
    t.knots = g.attr_ints("knots");
    t.desc.input_dim = term.dim();
    t.desc.activation = g.attr_string("activation");
    t.desc.hidden = g.attr_ints("hidden");
    t.norm.center = g.attr_doubles("in_center");
    t.norm.halfwidth = g.attr_doubles("in_halfwidth");
    t.norm.out_mean = g.attr_double("out_mean");
    t.norm.out_std = g.attr_double("out_std");
    t.epochs = static_cast<int>(g.attr_int("epochs"));
    t.backend = g.attr_string("backend");
    t.status = g.attr_string("status");
    // Files written before the attribute existed all continue with the safeguard.
    if (g.has_attr("extrapolation")) t.extrapolation = g.attr_string("extrapolation");
    if (t.knots.size() != size_t(term.dim()))
      g.fail(g.path(), "attribute knots must have " + std::to_string(term.dim()) + " entries");
    std::vector<hsize_t> dims;
    const int max_knots = term.dim() == 1 ? kMaxKnots1D : kMaxKnots2D;
    for (int k : t.knots) {
      if (k < 2) g.fail(g.path(), "fewer than 2 knots on an axis");
      if (k > max_knots)
        g.fail(g.path(), "attribute knots: " + std::to_string(k) + " knots on an axis, more than the " +
                             std::to_string(max_knots) + " a " + std::to_string(term.dim()) + "D table may have");
      dims.push_back(hsize_t(k));
    }
    // The arrays' declared shapes are checked against the knot counts before they are read.
    auto read = [&](const std::string& name, const std::vector<hsize_t>& want) {
      return g.read_double(name, std::vector<int64_t>(want.begin(), want.end())).data;
    };
    t.f = read("f", dims);
    t.f_x = read("f_x", dims);
    if (term.dim() == 1) {
      auto lo = g.attr_doubles("safeguard_lower"), hi = g.attr_doubles("safeguard_upper");
      if (lo.size() != 3 || hi.size() != 3)
        g.fail(g.path(), "attributes safeguard_lower/upper must have 3 entries [a, b, c]");
      std::copy(lo.begin(), lo.end(), t.safeguard_lower.begin());
      std::copy(hi.begin(), hi.end(), t.safeguard_upper.begin());
    } else {
      t.f_y = read("f_y", dims);
      t.f_xy = read("f_xy", dims);
      for (int e = 0; e < 4; ++e)
        t.edges[e] = read(std::string("safeguard/") + kBakedEdgeNames[e], {dims[e < 2 ? 1 : 0], 6});
      for (int c = 0; c < 4; ++c) {
        auto v = read(std::string("safeguard/") + kBakedCornerNames[c], {8});
        std::copy(v.begin(), v.end(), t.corners[c].begin());
      }
    }
    m.tables.push_back(std::move(t));
  }
  validate_baked(m, path);
  return m;
}

}  // namespace yarnhom
