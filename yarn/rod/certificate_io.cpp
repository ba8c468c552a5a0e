#include "yarn/rod/certificate_io.hpp"

#include <cmath>
#include <limits>

namespace yarnhom::yarn {

h5::Node write_certificate(h5::Node& root, const ContactCertificate& c) {
  h5::Node cg = root.create_group("certificate");
  cg.set_attr("valid", c.valid ? 1 : 0);
  cg.set_attr("dmin", c.dmin);
  cg.set_attr("min_distance", std::isfinite(c.min_distance) ? c.min_distance : -1.0);
  cg.set_attr("moves", c.moves);
  cg.set_attr("failure", c.failure);
  return cg;
}

ContactCertificate read_certificate(const h5::Node& root, double dmin, const std::string& missing) {
  ContactCertificate c;
  c.dmin = dmin;
  if (!root.has("certificate")) {
    invalidate(c, missing);
    return c;
  }
  const h5::Node cg = root.group("certificate");
  c.valid = cg.attr_int("valid") != 0;
  c.dmin = cg.attr_double("dmin");
  c.min_distance = cg.attr_double("min_distance");
  if (c.min_distance < 0) c.min_distance = std::numeric_limits<double>::infinity();
  c.moves = static_cast<int>(cg.attr_int("moves"));
  c.failure = cg.attr_string("failure");
  if (c.dmin != dmin) invalidate(c, "certified against another d_min than this problem's");
  return c;
}

}  // namespace yarnhom::yarn
