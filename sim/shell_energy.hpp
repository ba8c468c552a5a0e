#pragma once
// The shell's elastic energy (spec section 10): E(x) = sum_T A_T Psi(s_T(x)), with its
// gradient and its Hessian by the chain rule through s,
//   dE/dq = A J^T g,   d2E/dq2 = A (J^T H J + sum_k g_k d2s_k/dq2),
// (g, H) = (dPsi/ds, d2Psi/ds2) of the material at s_T, J = ds/dq (sim/shell_strain.hpp);
// each element's Hessian is replaced by a positive semi-definite model (sim/hessian_model.hpp)
// before assembly.
// Elements are evaluated in parallel (OpenMP); each thread accumulates into its own arrays.
#include <vector>

#include "sim/element_rest.hpp"
#include "sim/hessian_model.hpp"
#include "sim/hessian_pattern.hpp"
#include "material/material_fn.hpp"
#include "numerics/psd_projection.hpp"
#include "sim/mesh.hpp"

namespace yarnhom::sim {

std::vector<ElementRest> make_element_rests(const Mesh& mesh);

// CPU seconds summed over threads, for the --profile split.
struct ShellTimings {
  double strain = 0, material = 0, chain = 0, project = 0, scatter = 0;
  long elements = 0, projected = 0;
  ShellTimings& operator+=(const ShellTimings& o) {
    strain += o.strain;
    material += o.material;
    chain += o.chain;
    project += o.project;
    scatter += o.scatter;
    elements += o.elements;
    projected += o.projected;
    return *this;
  }
};

// theta_ref (optional, everywhere below): 3 per triangle, the branches of its dihedral angles
// (sim/hinge_angles.hpp); null: every angle in (-pi, pi].

// Value only (the line search's call). x: 3n, vertex-major. value (if given and set): the
// material's psi alone, used instead of psi's full evaluation (the same value, bit for bit,
// without the derivatives: material/material_fn.hpp).
double shell_energy(const Mesh& mesh, const std::vector<ElementRest>& rest, const MaterialFn& psi,
                    const Eigen::VectorXd& x, const double* theta_ref = nullptr, const MaterialValueFn* value = nullptr);

// Value; gradient added to grad (3n, all vertices); if pattern and values are given, the
// element Hessians added to values (free vertices only), in the given model (Exact: tests
// compare it with finite differences).
// move, coupling (optional, with the Hessian): sum over the elements of H_e move_e, the model
// Hessian applied to a displacement (3n), added to coupling (3n, every vertex). The one-solve
// step gives it its prescribed vertices' move, so that the free vertices' part, H_fp d_p, is the
// pull of the handles' move on the cloth in the solve (sim/newton.hpp). Elements the move does
// not touch are skipped.
double shell_energy_derivatives(const Mesh& mesh, const std::vector<ElementRest>& rest, const MaterialFn& psi,
                                const Eigen::VectorXd& x, Eigen::VectorXd& grad, const HessianPattern* pattern,
                                double* values, ShellTimings* timings = nullptr,
                                HessianModel model = HessianModel::ProjectedElement,
                                const double* theta_ref = nullptr,
                                numerics::EigenFilter filter = numerics::EigenFilter::Clamp,
                                const Eigen::VectorXd* move = nullptr, Eigen::VectorXd* coupling = nullptr);

// Per-triangle strain at x (for output and tests).
std::vector<Strain6> triangle_strains(const Mesh& mesh, const std::vector<ElementRest>& rest, const Eigen::VectorXd& x,
                                      const double* theta_ref = nullptr);

}  // namespace yarnhom::sim
