#include "yarn/strip/strip_contact.hpp"

#include "numerics/ccd.hpp"

namespace yarnhom::yarn {

using numerics::Vec12;
using numerics::Mat12;
using numerics::segment_barrier_energy;
using numerics::segment_ccd;

StripContact::StripContact(double radius, double kc, const StripContactOptions& o)
    : kernel_{radius, kc, o.quadrature},
      barrier_{o.dmin * 2 * radius, o.dhat * 2 * radius, o.barrier_stiffness * kc * 4 * radius * radius} {}

StripContact::Energy StripContact::energy(const Vec12& q, double La, double Lb, Vec12* g, Mat12* H) const {
  Energy e;
  e.kernel = segment_contact_energy(q, La, Lb, kernel_, g, H);
  Vec12 gb;
  Mat12 Hb;
  e.barrier = segment_barrier_energy(q, barrier_, g ? &gb : nullptr, H ? &Hb : nullptr);
  if (g) *g += gb;
  if (H) *H += Hb;
  return e;
}

double StripContact::safe_fraction(const Vec12& q0, const Vec12& q1) const {
  return segment_ccd(q0, q1, barrier_.dmin).t;
}

}  // namespace yarnhom::yarn
