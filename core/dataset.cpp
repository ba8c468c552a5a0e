#include "core/dataset.hpp"

#include <cmath>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/h5.hpp"

namespace yarnhom {

const TermData* Dataset::find(const std::string& name) const { return find_term(terms, name); }

namespace {

void check_finite(const std::vector<double>& v, const std::string& file, const std::string& obj) {
  for (size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw FileError(file, obj, "non-finite value at flat index " + std::to_string(i));
}

}  // namespace

void validate_dataset(const Dataset& ds, const std::string& file) {
  if (ds.terms.empty()) throw FileError(file, "/terms", "no terms");
  if (!std::isfinite(ds.psi0)) throw FileError(file, "/rest", "psi0 is not finite");
  auto optional_attr = [&](const std::vector<double>& v, size_t n, const char* name) {
    if (v.empty()) return;
    if (v.size() != n)
      throw FileError(file, "/rest", std::string("attribute ") + name + " must have " + std::to_string(n) + " entries");
    check_finite(v, file, std::string("/rest ") + name);
  };
  optional_attr(ds.lattice_original, 4, "lattice_original");
  optional_attr(ds.lattice_relaxed, 4, "lattice_relaxed");
  optional_attr(ds.grad0, 6, "grad0");
  optional_attr(ds.rest_hessian, 36, "hessian");
  optional_attr(ds.rve_tiles, 2, "rve_tiles");
  for (double t : ds.rve_tiles)
    if (t != std::floor(t) || t < 1 || t > 64)
      throw FileError(file, "/rest", "attribute rve_tiles must hold two whole numbers in [1, 64]");
  for (int i = 0; i < 6 && ds.rest_hessian.size() == 36; ++i)
    for (int j = 0; j < i; ++j)
      if (ds.rest_hessian[i * 6 + j] != ds.rest_hessian[j * 6 + i])
        throw FileError(file, "/rest", "attribute hessian is not symmetric (entries " + std::to_string(i * 6 + j) +
                                           " and " + std::to_string(j * 6 + i) + ")");
  if (!std::isnan(ds.areal_density) && !(ds.areal_density > 0 && std::isfinite(ds.areal_density)))
    throw FileError(file, "/", "areal_density must be positive and finite (absent when unknown)");
  for (const TermData& t : ds.terms) {
    const std::string g = "/terms/" + t.term.name;
    const size_t d = t.dim();
    if (t.n < 2) throw FileError(file, g, "fewer than 2 samples (" + std::to_string(t.n) + ")");
    if (t.strain.size() != t.n * d)
      throw FileError(file, g + "/strain", "wrong shape: expected [" + std::to_string(t.n) + ", " +
                                               std::to_string(d) + "]");
    if (t.energy.size() != size_t(t.n))
      throw FileError(file, g + "/energy", "wrong shape: expected [" + std::to_string(t.n) + "]");
    if (t.gradient.size() != t.n * d)
      throw FileError(file, g + "/gradient", "wrong shape: expected [" + std::to_string(t.n) +
                                                 ", " + std::to_string(d) + "]");
    if (t.raw.size() != size_t(t.n))
      throw FileError(file, g + "/raw", "wrong shape: expected [" + std::to_string(t.n) + "]");
    if (t.lower.size() != d || t.upper.size() != d)
      throw FileError(file, g, "attributes lower/upper must have " + std::to_string(d) + " entries");
    check_finite(t.strain, file, g + "/strain");
    check_finite(t.energy, file, g + "/energy");
    check_finite(t.gradient, file, g + "/gradient");
    check_finite(t.raw, file, g + "/raw");
    for (size_t k = 0; k < d; ++k)
      if (!(t.lower[k] < t.upper[k]) || !std::isfinite(t.lower[k]) || !std::isfinite(t.upper[k]))
        throw FileError(file, g, "empty or non-finite box: lower must be below upper");
  }
}

Dataset read_dataset(const std::string& path) {
  h5::Node root = h5::open_file(path);
  Dataset ds;
  if (!root.has_attr("format") || root.attr_string("format") != kDatasetFormat)
    root.fail("/", std::string("not a yarnhom dataset (attribute format must be '") +
                       kDatasetFormat + "')");
  if (root.attr_int("version") != kDatasetVersion)
    root.fail("/", "unsupported dataset version " + std::to_string(root.attr_int("version")));
  ds.pattern = root.has_attr("pattern") ? root.attr_string("pattern") : "";
  ds.source = root.has_attr("source") ? root.attr_string("source") : "";
  ds.note = root.has_attr("note") ? root.attr_string("note") : "";
  if (root.has_attr("areal_density")) ds.areal_density = root.attr_double("areal_density");
  h5::Node rest = root.group("rest");
  ds.psi0 = rest.attr_double("psi0");
  if (rest.has_attr("lattice_original")) ds.lattice_original = rest.attr_doubles("lattice_original");
  if (rest.has_attr("lattice_relaxed")) ds.lattice_relaxed = rest.attr_doubles("lattice_relaxed");
  if (rest.has_attr("grad0")) ds.grad0 = rest.attr_doubles("grad0");
  if (rest.has_attr("hessian")) ds.rest_hessian = rest.attr_doubles("hessian");
  if (rest.has_attr("rve_tiles")) ds.rve_tiles = rest.attr_doubles("rve_tiles");
  if (rest.has("q")) {
    ds.rest_q = rest.read_double("q", {-1}).data;
    check_finite(ds.rest_q, path, "/rest/q");
  }
  h5::Node terms = root.group("terms");
  for (const std::string& name : terms.children()) {
    TermData t;
    try {
      t.term = term_by_name(name);
    } catch (const std::invalid_argument& e) {
      terms.fail("/terms/" + name, e.what());
    }
    h5::Node g = terms.group(name);
    const size_t d = t.dim();
    auto indices = g.attr_ints("indices");
    if (indices != t.term.indices)
      g.fail(g.path(), "attribute indices does not match the term's strain indices");
    // N comes from the strain's declared shape; every other array must declare the same N,
    // checked before anything is read.
    const auto sdims = g.shape("strain");
    if (sdims.size() != 2 || sdims[1] != d)
      g.fail(g.child_path("strain"), "wrong shape " + h5::shape_string(sdims) + ", expected [N, " + std::to_string(d) + "]");
    if (sdims[0] > kMaxSamples)
      g.fail(g.child_path("strain"), "declares " + std::to_string(sdims[0]) + " samples, more than the " +
                                         std::to_string(kMaxSamples) + " a term may have");
    const int64_t N = static_cast<int64_t>(sdims[0]), D = static_cast<int64_t>(d);
    t.n = static_cast<int>(N);
    t.strain = g.read_double("strain", {N, D}).data;
    t.energy = g.read_double("energy", {N}).data;
    t.gradient = g.read_double("gradient", {N, D}).data;
    t.raw = g.read_double("raw", {N}).data;
    t.lower = g.attr_doubles("lower");
    t.upper = g.attr_doubles("upper");
    ds.terms.push_back(std::move(t));
  }
  // Catalogue order, whatever order HDF5 listed them in.
  std::vector<TermData> ordered;
  for (const Term& term : all_terms())
    for (TermData& t : ds.terms)
      if (t.term.name == term.name) ordered.push_back(std::move(t));
  ds.terms = std::move(ordered);
  validate_dataset(ds, path);
  return ds;
}

void write_dataset(const std::string& path, const Dataset& ds) {
  validate_dataset(ds, path);
  AtomicOutput out(path);
  {
    h5::Node root = h5::create_file(out.temp_path(), kDatasetFormat, kDatasetVersion);
    root.set_attr("pattern", ds.pattern);
    root.set_attr("units", "SI");
    root.set_attr("source", ds.source);
    if (!ds.note.empty()) root.set_attr("note", ds.note);
    if (!std::isnan(ds.areal_density)) root.set_attr("areal_density", ds.areal_density);
    h5::Node rest = root.create_group("rest");
    rest.set_attr("psi0", ds.psi0);
    if (!ds.lattice_original.empty()) rest.set_attr("lattice_original", ds.lattice_original);
    if (!ds.lattice_relaxed.empty()) rest.set_attr("lattice_relaxed", ds.lattice_relaxed);
    if (!ds.grad0.empty()) rest.set_attr("grad0", ds.grad0);
    if (!ds.rest_hessian.empty()) rest.set_attr("hessian", ds.rest_hessian);
    if (!ds.rve_tiles.empty()) rest.set_attr("rve_tiles", ds.rve_tiles);
    rest.write("q", ds.rest_q, {ds.rest_q.size()});
    h5::Node terms = root.create_group("terms");
    for (const TermData& t : ds.terms) {
      h5::Node g = terms.create_group(t.term.name);
      const hsize_t n = t.n, d = t.dim();
      g.write("strain", t.strain, {n, d});
      g.write("energy", t.energy, {n});
      g.write("gradient", t.gradient, {n, d});
      g.write("raw", t.raw, {n});
      g.set_attr("indices", t.term.indices);
      g.set_attr("lower", t.lower);
      g.set_attr("upper", t.upper);
    }
  }  // file closed before the rename
  out.commit();
}

}  // namespace yarnhom
