#include "yarn/rod/contact_certificate.hpp"

#include <algorithm>
#include <cstdio>

namespace yarnhom::yarn {

void invalidate(ContactCertificate& c, const std::string& why) {
  if (c.valid) c.failure = why;
  c.valid = false;
}

void add_move(ContactCertificate& c, double safe, double end_distance, const std::string& what) {
  ++c.moves;
  c.min_distance = std::min(c.min_distance, end_distance);
  if (safe < 1.0 || !(end_distance > c.dmin)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "move %d (%s) reaches d_min at %.3g of its length", c.moves, what.c_str(),
                  std::min(safe, 1.0));
    invalidate(c, buf);
  }
}

std::string summary(const ContactCertificate& c, double two_r) {
  char buf[256];
  if (c.valid)
    std::snprintf(buf, sizeof buf, "valid: closest centrelines %.4g x 2r over %d moves (d_min %.3g x 2r)",
                  c.min_distance / two_r, c.moves, c.dmin / two_r);
  else
    std::snprintf(buf, sizeof buf, "INVALID: %s (d_min %.3g x 2r)", c.failure.c_str(), c.dmin / two_r);
  return buf;
}

}  // namespace yarnhom::yarn
