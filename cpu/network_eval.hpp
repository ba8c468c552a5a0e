#pragma once
// A trained network evaluated in physical units: Psi_hat(s) and its derivatives with respect
// to the strain s, up to third order. With x = (s - c)/h and Psi = mu + sigma y(x):
//   dPsi/ds_i = sigma/h_i y_i,  d2Psi/ds_i ds_j = sigma/(h_i h_j) y_ij,  and so on.
#include <vector>

#include "core/model.hpp"

namespace yarnhom::cpu {

// s: [n, d] row-major physical strains. Returns [C, n] channel-major, C = jet_channels(d, order),
// channels as in core/jet_layout.hpp. Evaluated in double from the stored float weights.
std::vector<double> eval_network_physical(const ModelNetwork& net, const double* s, int n,
                                          int order = 3);

}  // namespace yarnhom::cpu
