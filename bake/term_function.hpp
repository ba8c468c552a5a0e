#pragma once
// One energy term as a function of its strains with derivatives, whatever computes it: a
// trained network (exact jet derivatives), a baked table, or an analytic test function. The
// metrics (quadratic expansion error, bake accuracy) and the baking itself take this type, so
// each is written once and checked on functions whose answers are known.
#include <functional>
#include <vector>

#include "bake/baked_eval.hpp"
#include "core/model.hpp"

namespace yarnhom {

// s: [n, d] row-major physical strains. Returns [C, n] channel-major with
// C = jet_channels(d, order) in the layout of core/jet_layout.hpp (order <= 3).
using TermFunction = std::function<std::vector<double>(const double* s, int n, int order)>;

TermFunction network_function(const ModelNetwork& net);  // keeps a copy of the network
TermFunction baked_function(const BakedTerm& term);      // keeps a copy of the table

}  // namespace yarnhom
