#pragma once
// The attributes a term's group carries in both the model file and the baked file
// (docs/conventions.md sections 7 and 8): its strain indices and box, and its network's shape and
// normalization. Written in one place so that the two formats cannot drift apart.
#include <string>
#include <vector>

#include "core/h5.hpp"
#include "core/model.hpp"

namespace yarnhom {

// indices, lower, upper.
void write_box_attrs(const h5::Node& g, const Term& term, const std::vector<double>& lower,
                     const std::vector<double>& upper);
// activation, hidden, in_center, in_halfwidth, out_mean, out_std.
void write_network_attrs(const h5::Node& g, const NetworkDesc& desc, const Normalization& norm);

}  // namespace yarnhom
