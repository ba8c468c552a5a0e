#include "material/material_source.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <stdexcept>

#include "core/baked.hpp"
#include "core/file_checks.hpp"
#include "core/h5.hpp"
#include "material/hylc_material.hpp"

namespace yarnhom {

namespace {

bool looks_like_json(const std::string& path) {
  std::ifstream in(path);
  char c = 0;
  while (in.get(c))
    if (!std::isspace(static_cast<unsigned char>(c))) return c == '{';
  return false;
}

// The box of a HYLC material: its in-plane 1D splines' knot ranges and its bending splines'
// largest |knot| (physical units); the conventions' defaults where a spline is absent.
GuardBox hylc_guard_box(const HylcMaterial& m) {
  GuardBox b;
  double c = 0;
  for (const HylcSpline1D& sp : m.d1) {
    if (sp.t.empty()) continue;
    const double sc = m.scale[sp.k];
    if (sp.k < 3) {
      b.lo[sp.k] = std::min(sp.t.front(), sp.t.back()) * sc;
      b.hi[sp.k] = std::max(sp.t.front(), sp.t.back()) * sc;
    } else {
      c = std::max({c, std::abs(sp.t.front() * sc), std::abs(sp.t.back() * sc)});
    }
  }
  if (c > 0) b.curvature = c;
  return b;
}

}  // namespace

LoadedMaterial load_material(const std::string& path) {
  check_input_file(path, "material");  // a FIFO would block the reader
  std::ifstream probe(path);
  if (!probe) throw std::invalid_argument(path + ": cannot open material file");
  probe.close();
  LoadedMaterial out;
  if (looks_like_json(path)) {
    auto mat = std::make_shared<HylcMaterial>(read_hylc_material(path));
    out.kind = "hylc";
    if (mat->density > 0) out.areal_density = mat->density;
    out.guard = std::make_shared<const CollapseGuard>(make_collapse_guard(hylc_guard_box(*mat), [mat](const Strain6& s) {
      return eval_hylc_material(*mat, s);
    }));
    out.fn = guarded_material_fn([mat](const Strain6& s) { return eval_hylc_material(*mat, s); }, out.guard);
    return out;
  }
  if (!is_baked_file(path)) {
    bool model = false;
    try {
      const h5::Node f = h5::open_file(path);
      model = f.has_attr("format") && f.attr_string("format") == "yarnhom-model";
    } catch (const std::exception&) {
    }
    if (model) throw std::invalid_argument(path + ": a model file; the simulator runs baked tables: run `yarnhom bake " + path + " -o BAKED.h5` first");
    throw std::invalid_argument(path + ": not a material: expected a baked file (yarnhom bake) or a HYLC material JSON");
  }
  const BakedModel bm = read_baked(path);
  auto mat = std::make_shared<BakedMaterial>(make_baked_material(bm, path, &out.missing_terms));
  out.kind = "baked";
  out.fn = baked_material_fn(mat, &out.guard);
  out.value = baked_material_value_fn(mat, out.guard);
  if (std::isfinite(bm.areal_density) && bm.areal_density > 0) out.areal_density = bm.areal_density;
  return out;
}

}  // namespace yarnhom
