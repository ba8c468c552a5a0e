#pragma once
// The material as the simulator sees it: Psi(s) with its gradient and Hessian in the strain
// 6-vector (spec section 8b), whatever computes it: a baked file (material/material.hpp) or a
// HYLC material JSON (material/hylc_material.hpp).
#include <functional>
#include <memory>

#include "material/collapse_guard.hpp"
#include "material/material.hpp"

namespace yarnhom {

using MaterialFn = std::function<MaterialEval(const Strain6&)>;
// Psi alone, where a material has a cheaper path for it than MaterialFn's (bit for bit its psi).
using MaterialValueFn = std::function<double(const Strain6&)>;

// The tables alone (eval_material), keeping the material alive in the closure.
inline MaterialFn baked_tables_fn(std::shared_ptr<const BakedMaterial> mat) {
  return [mat](const Strain6& s) { return eval_material(*mat, s); };
}

// What a simulator runs: any material with the collapse guard around it
// (material/collapse_guard.hpp).
inline MaterialFn guarded_material_fn(MaterialFn tables, std::shared_ptr<const CollapseGuard> guard) {
  return [tables = std::move(tables), guard](const Strain6& s) {
    MaterialEval e = tables(s);
    add_collapse_guard(*guard, s, e);
    return e;
  };
}

// A baked material as the simulator runs it: the tables and the guard around their boxes.
inline MaterialFn baked_material_fn(std::shared_ptr<const BakedMaterial> mat,
                                    std::shared_ptr<const CollapseGuard>* guard_out = nullptr) {
  MaterialFn tables = baked_tables_fn(mat);
  auto guard = std::make_shared<const CollapseGuard>(make_collapse_guard(baked_guard_box(*mat), tables));
  if (guard_out) *guard_out = guard;
  return guarded_material_fn(std::move(tables), guard);
}

// baked_material_fn's psi alone: the tables' values and the guard's, in its order.
inline MaterialValueFn baked_material_value_fn(std::shared_ptr<const BakedMaterial> mat,
                                               std::shared_ptr<const CollapseGuard> guard) {
  return [mat, guard](const Strain6& s) { return add_collapse_guard_value(*guard, s, eval_material_value(*mat, s)); };
}

}  // namespace yarnhom
