#pragma once
// The contact model of yarn strips behind one small interface (one place to change it): the
// energy of a pair of segments, how far that energy reaches (for the broad phase), the
// collision filter along a straight move, and the closest distance (the certificate). It is
// the RVE's (docs/rve.md section 3), built from issue 10's free functions:
//
//   - the integrated penalty kernel (yarn/rod/contact.hpp), the physical contact response;
//   - IPC's log barrier on the exact closest distance (numerics/barrier.hpp,
//     numerics/segment_distance.hpp): +inf at d_min, zero beyond d_hat, so that no configuration
//     with a pair at d_min has finite energy;
//   - conservative-advancement CCD against d_min (numerics/ccd.hpp) for every straight move.
//
// Distances in yarn diameters 2r as in RveOptions: d_min 0.25, d_hat 0.5, barrier energy
// scale k_c (2r)^2; physical equilibria keep their centrelines above 0.62 x 2r (measured for
// the RVE), where the barrier is zero.
#include <Eigen/Core>

#include "numerics/barrier.hpp"
#include "yarn/rod/contact.hpp"
#include "numerics/segment_distance.hpp"

namespace yarnhom::yarn {

using numerics::Vec12;
using numerics::Mat12;
using numerics::segment_distance;
using numerics::BarrierParams;

struct StripContactOptions {
  int quadrature = 4;             // kernel Gauss points per segment
  double dmin = 0.25;             // barrier: +inf at this distance (in 2r)
  double dhat = 0.5;              // barrier: zero beyond (in 2r)
  double barrier_stiffness = 1.0; // barrier energy scale in k_c (2r)^2
};

class StripContact {
 public:
  StripContact(double radius, double kc, const StripContactOptions& o = {});

  double radius() const { return kernel_.radius; }
  // Centreline distance beyond which a pair has no energy (the kernel's 2r; d_hat < 2r).
  double reach() const { return 2.0 * kernel_.radius; }
  double dmin() const { return barrier_.dmin; }  // m

  struct Energy {
    double kernel = 0, barrier = 0;  // J; barrier +inf at or below d_min
    double total() const { return kernel + barrier; }
  };
  // q = [a0, a1, b0, b1]; La, Lb the segments' rest lengths; g, H (when given) receive the
  // gradient and Hessian of the total.
  Energy energy(const Vec12& q, double La, double Lb, Vec12* g, Mat12* H) const;
  // The fraction of the straight move q0 -> q1 along which the pair stays above d_min
  // (1: all of it).
  double safe_fraction(const Vec12& q0, const Vec12& q1) const;

 private:
  ContactParams kernel_;
  BarrierParams barrier_;
};

// Closest distance of the pair q = [a0, a1, b0, b1].
inline double pair_distance(const Vec12& q) {
  return segment_distance(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
}

}  // namespace yarnhom::yarn
