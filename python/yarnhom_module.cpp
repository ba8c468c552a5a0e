// The Python module `yarnhom` (pybind11): a baked file or a HYLC material JSON, loaded as the
// simulator loads it (material/material_source.hpp), evaluated at given strains: energy Psi
// (J/m^2), stress dPsi/ds (N/m for the in-plane strains, N for the curvatures) and tangent
// stiffness d2Psi/ds2, in the strain 6-vector s = (s_x, s_a, s_y, II_x, II_a, II_y) of
// docs/conventions.md; and one baked term's jet, column for column what `yarnhom eval` prints.
// A room of its own above every other (docs/layout.md): it only calls material/ and core/.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "core/baked.hpp"
#include "core/jet_layout.hpp"
#include "core/terms.hpp"
#include "material/baked_eval.hpp"
#include "material/hylc_material.hpp"
#include "material/material_source.hpp"

namespace py = pybind11;
using namespace yarnhom;

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

bool is_json(const std::string& path) {
  const size_t n = path.size();
  return n > 5 && path.compare(n - 5, 5, ".json") == 0;
}

// A material: with the collapse guard (what `sim` runs) or the tables alone.
class Material {
 public:
  Material(const std::string& path, bool guard) : path_(path) {
    const LoadedMaterial m = load_material(path);  // checks the file, says what it is
    kind_ = m.kind;
    missing_ = m.missing_terms;
    density_ = m.areal_density ? *m.areal_density : NAN;
    if (guard) {
      fn_ = m.fn;
    } else if (kind_ == "hylc" || is_json(path)) {
      auto h = std::make_shared<HylcMaterial>(read_hylc_material(path));
      fn_ = [h](const Strain6& s) { return eval_hylc_material(*h, s); };
    } else {
      auto b = std::make_shared<BakedMaterial>(make_baked_material(read_baked(path), path));
      fn_ = [b](const Strain6& s) { return eval_material(*b, s); };
    }
  }

  // strains: [6] or [N, 6]. Returns (psi [N], stress [N, 6], tangent [N, 6, 6]) (N dropped for [6]).
  py::tuple evaluate(const Array& strains) const {
    const bool one = strains.ndim() == 1;
    if (!((one && strains.shape(0) == 6) || (strains.ndim() == 2 && strains.shape(1) == 6)))
      throw std::invalid_argument("strains: expected shape (6,) or (N, 6): s_x, s_a, s_y, II_x, II_a, II_y");
    const py::ssize_t n = one ? 1 : strains.shape(0);
    Array psi(std::vector<py::ssize_t>{n}), stress(std::vector<py::ssize_t>{n, 6}), tangent(std::vector<py::ssize_t>{n, 6, 6});
    const double* s = strains.data();
    double *p = psi.mutable_data(), *g = stress.mutable_data(), *h = tangent.mutable_data();
    for (py::ssize_t k = 0; k < n; ++k) {
      const Strain6 e = Eigen::Map<const Strain6>(s + 6 * k);
      if (!e.allFinite()) throw std::invalid_argument("strains: row " + std::to_string(k) + " is not finite");
      const MaterialEval r = fn_(e);
      p[k] = r.psi;
      for (int i = 0; i < 6; ++i) {
        g[6 * k + i] = r.grad[i];
        for (int j = 0; j < 6; ++j) h[36 * k + 6 * i + j] = r.hess(i, j);
      }
    }
    if (one) return py::make_tuple(py::float_(p[0]), stress.reshape({6}), tangent.reshape({6, 6}));
    return py::make_tuple(psi, stress, tangent);
  }

  std::string path_, kind_, missing_;
  double density_ = NAN;

 private:
  MaterialFn fn_;
};

// One term of a baked file at points [N, d]: [N, C] with the columns of `yarnhom eval` (psi,
// first, second, third derivatives; core/jet_layout.hpp), safeguard included outside the box.
Array term_jet(const std::string& path, const std::string& term, const Array& points, int order) {
  if (order < 0 || order > 3) throw std::invalid_argument("order: 0 to 3");
  const BakedModel bm = read_baked(path);
  const BakedTable* t = bm.find(term);
  if (!t) throw std::invalid_argument(path + ": no table for term '" + term + "'");
  const BakedTerm bt = make_baked_term(*t, path);
  const int d = t->dim(), C = jet_channels(d, order);
  const bool one = points.ndim() == 1 && points.shape(0) == d;
  if (!one && !(points.ndim() == 2 && points.shape(1) == d))
    throw std::invalid_argument("points: expected shape (N, " + std::to_string(d) + ") for term " + term);
  const py::ssize_t n = one ? 1 : points.shape(0);
  Array out(std::vector<py::ssize_t>{n, C});
  double j[kMaxJetChannels];
  for (py::ssize_t p = 0; p < n; ++p) {
    eval_baked_jet(bt, points.data() + d * p, order, j);
    for (int c = 0; c < C; ++c) out.mutable_data()[C * p + c] = j[c];
  }
  return one ? out.reshape({C}) : out;
}

// The column names of term_jet (as `yarnhom eval`'s header, after the strains).
std::vector<std::string> term_columns(const std::string& term, int order) {
  const Term t = term_by_name(term);
  const int d = t.dim();
  auto sym = [&](int i) { return std::string(kStrainSymbols[t.indices[i]]); };
  std::vector<std::string> names = {"psi"};
  if (order >= 1)
    for (int i = 0; i < d; ++i) names.push_back("d/d" + sym(i));
  if (order >= 2)
    for (int q = 0; q < jet_num_pairs(d); ++q) names.push_back("d2/d" + sym(jet_pair(d, q).i) + "/d" + sym(jet_pair(d, q).j));
  if (order >= 3)
    for (int q = 0; q < jet_num_triples(d); ++q) {
      const JetTriple e = jet_triple(d, q);
      names.push_back("d3/d" + sym(e.i) + "/d" + sym(e.j) + "/d" + sym(e.k));
    }
  return names;
}

}  // namespace

PYBIND11_MODULE(yarnhom, m) {
  m.doc() = "yarnhom's materials in Python: load a baked file or a HYLC material JSON, evaluate energy, stress "
            "and tangent stiffness at strains s = (s_x, s_a, s_y, II_x, II_a, II_y) (docs/python.md)";
  py::class_<Material>(m, "Material")
      .def(py::init<const std::string&, bool>(), py::arg("path"), py::arg("guard") = true,
           "Loads a baked file (yarnhom bake) or a HYLC material JSON; guard=True adds the collapse guard, as sim runs it")
      .def("evaluate", &Material::evaluate, py::arg("strains"),
           "(psi, stress, tangent) at strains of shape (6,) or (N, 6): J/m^2, dPsi/ds, d2Psi/ds2")
      .def("energy", [](const Material& M, const Array& s) { return py::object(M.evaluate(s)[0]); }, py::arg("strains"))
      .def("stress", [](const Material& M, const Array& s) { return py::object(M.evaluate(s)[1]); }, py::arg("strains"))
      .def("tangent", [](const Material& M, const Array& s) { return py::object(M.evaluate(s)[2]); }, py::arg("strains"))
      .def_readonly("path", &Material::path_)
      .def_readonly("kind", &Material::kind_, "'baked' or 'hylc'")
      .def_readonly("missing_terms", &Material::missing_, "terms absent from a baked file (they count as zero)")
      .def_readonly("areal_density", &Material::density_, "kg/m^2, NaN when the file does not say");
  m.def("term_jet", &term_jet, py::arg("path"), py::arg("term"), py::arg("points"), py::arg("order") = 3,
        "One term of a baked file at points (N, d): (N, C), the columns of `yarnhom eval` (term_columns)");
  m.def("term_columns", &term_columns, py::arg("term"), py::arg("order") = 3);
  m.attr("strain_names") = py::make_tuple("s_x", "s_a", "s_y", "II_x", "II_a", "II_y");
}
