#pragma once
// The topology certificate in a file: the group "certificate" of an RVE state file and of a
// strip step file carries the same attributes (valid, dmin, min_distance with -1 for none,
// moves, failure); each file adds its own extras to the group.
#include <string>

#include "core/h5.hpp"
#include "yarn/rod/contact_certificate.hpp"

namespace yarnhom::yarn {

// Creates root/certificate with c's attributes and returns it (for the caller's extras).
h5::Node write_certificate(h5::Node& root, const ContactCertificate& c);

// The certificate root/certificate states; without that group (a file written before
// certificates existed) an invalid one that says `missing`. A certificate made against another
// d_min than `dmin` is invalidated: it certifies nothing for this problem.
ContactCertificate read_certificate(const h5::Node& root, double dmin, const std::string& missing);

}  // namespace yarnhom::yarn
