#include "core/term_attrs.hpp"

namespace yarnhom {

void write_box_attrs(const h5::Node& g, const Term& term, const std::vector<double>& lower,
                     const std::vector<double>& upper) {
  g.set_attr("indices", term.indices);
  g.set_attr("lower", lower);
  g.set_attr("upper", upper);
}

void write_network_attrs(const h5::Node& g, const NetworkDesc& desc, const Normalization& norm) {
  g.set_attr("activation", desc.activation);
  g.set_attr("hidden", desc.hidden);
  g.set_attr("in_center", norm.center);
  g.set_attr("in_halfwidth", norm.halfwidth);
  g.set_attr("out_mean", norm.out_mean);
  g.set_attr("out_std", norm.out_std);
}

}  // namespace yarnhom
