#pragma once
// The material as the simulator sees it: Psi(s) with its gradient and Hessian in the strain
// 6-vector (spec section 8b), whatever computes it: a baked file (material/material.hpp) or a
// HYLC material JSON (material/hylc_material.hpp).
#include <functional>
#include <memory>

#include "material/material.hpp"

namespace yarnhom {

using MaterialFn = std::function<MaterialEval(const Strain6&)>;

// Keeps the material alive in the closure.
inline MaterialFn baked_material_fn(std::shared_ptr<const BakedMaterial> mat) {
  return [mat](const Strain6& s) { return eval_material(*mat, s); };
}

}  // namespace yarnhom
