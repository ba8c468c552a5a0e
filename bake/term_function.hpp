#pragma once
// One energy term as a function of its strains with derivatives, whatever computes it: a
// trained network (exact jet derivatives), a baked table, or an analytic test function. The
// metrics (quadratic expansion error, bake accuracy) and the baking itself take this type, so
// each is written once and checked on functions whose answers are known.
#include <functional>
#include <vector>

#include "material/baked_eval.hpp"
#include "core/model.hpp"

namespace yarnhom {

// s: [n, d] row-major physical strains. Returns [C, n] channel-major with
// C = jet_channels(d, order) in the layout of core/jet_layout.hpp (order <= 3).
using TermFunction = std::function<std::vector<double>(const double* s, int n, int order)>;

TermFunction network_function(const ModelNetwork& net);  // keeps a copy of the network
TermFunction baked_function(const BakedTerm& term);      // keeps a copy of the table

// The term a network stands for in the material, i.e. what bake bakes. A 1D term is the
// network. A 2D term is a residual, Psi_IJ = Psi - Psi_I - Psi_J, which is 0 on both axes
// (s_I = 0 or s_J = 0) with its gradient along them, and so are its data; a network is 0 there
// only to its fit error, and that error adds to the material's stress at rest (on the paper's
// basket: -0.41 N/m of the -0.64 N/m a continuum strip pushed on its clamps at 100 %). So a 2D
// term is the network's axis projection
//   R(x, y) = N(x, y) - N(x, 0) - N(0, y) + N(0, 0),
// which vanishes on both axes (to rounding), leaves every mixed derivative (d/dx d/dy) the
// network's, and is the identity on any function that already vanishes there. Its jet channel
// (a, b) (a derivatives in x, b in y) is N_ab(x, y) - [b = 0] N_a0(x, 0) - [a = 0] N_0b(0, y) +
// [a = b = 0] N(0, 0). A box that does not contain 0 on both axes keeps the network.
TermFunction material_function(const ModelNetwork& net);
TermFunction axis_projection(const TermFunction& f, int dim);  // the projection of any 2D function

}  // namespace yarnhom
