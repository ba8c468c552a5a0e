#pragma once
// Which positive semi-definite model of an element's Hessian the Newton solves use. The exact
// element Hessian is
//
//   A (J^T H J + sum_k g_k d2s_k/dq2),   g = dPsi/ds, H = d2Psi/ds2, J = ds/dq (6 x 18),
//
// indefinite wherever the material is (compression, the softening branches of a trained
// model) and wherever the strain measure is curved against the stress (a compressed fibre's
// |f| term, the shear cosine, every dihedral angle's Hessian).
//
// ProjectedElement: the exact 18 x 18 matrix projected onto the PSD cone (IPC's way): the best
//   PSD approximation of the exact Hessian, at the cost of an 18 x 18 symmetric eigenproblem
//   per indefinite element (60 % of the assembly on a draped sheet, docs/benchmarks.md).
// Split: A (J^T [H]_+ J + C^T [Hf]_+ C), where [.]_+ projects a 6 x 6 matrix: H, and Hf the
//   in-plane curvature term sum_k g_k d2s_k/df2 over the in-plane strains in the variables
//   (f1, f2) = (F e1, F e2), linear in the vertices (f = C q; sim/inplane_strain.hpp). The
//   bending strains' curvature term sum_k g_k d2II_k/dq2 (moments times the dihedral angles'
//   and edge heights' Hessians) is left out: a Gauss-Newton model for bending. PSD by
//   construction (sums of congruences of PSD matrices), two 6 x 6 eigenproblems at most, and
//   equal to the exact Hessian wherever H and Hf are PSD and the bending moments g_3..5 vanish.
// Exact: no projection (tests compare it with finite differences).
#include <stdexcept>
#include <string>

namespace yarnhom::sim {

enum class HessianModel { Exact, ProjectedElement, Split };

inline HessianModel parse_hessian_model(const std::string& name) {
  if (name == "projected") return HessianModel::ProjectedElement;
  if (name == "split") return HessianModel::Split;
  if (name == "exact") return HessianModel::Exact;
  throw std::invalid_argument("hessian model '" + name + "': expected split, projected or exact");
}

inline const char* hessian_model_name(HessianModel m) {
  return m == HessianModel::Split ? "split" : m == HessianModel::ProjectedElement ? "projected" : "exact";
}

}  // namespace yarnhom::sim
