#pragma once
// The contact model of yarn strips behind one small interface, so that replacing it is one
// edit in strip_contact.cpp: the energy of a pair of segments, how far that energy reaches
// (for the broad phase), a step filter that keeps every pair from passing through each other
// along a Newton step, and the closest distance of two segments (the certificate).
//
// Today: yarn/contact.hpp's integrated penalty, the same energy as the RVE's, and a
// conservative step filter (along a linear step every point of a segment moves at most as far
// as its farther endpoint, so two segments at distance d stay at least d - t (m_a + m_b)
// apart after the fraction t of the step). Issue 10's barrier in the closest segment
// distance, its CCD step filter and its topology certificate replace these when they land.
#include <Eigen/Core>

#include "yarn/contact.hpp"

namespace yarnhom::yarn {

class StripContact {
 public:
  StripContact(double radius, double kc, int quadrature = 4) : params_{radius, kc, quadrature} {}

  double radius() const { return params_.radius; }
  // Centreline distance beyond which a pair of segments has no energy.
  double reach() const { return 2.0 * params_.radius; }
  // q = [a0, a1, b0, b1]; La, Lb the segments' rest lengths.
  double energy(const Vec12& q, double La, double Lb, Vec12* g, Mat12* H) const;
  // Largest t in (0, 1] such that moving the endpoints by t dq keeps the segments at least a
  // tenth of their present distance apart at every instant of the motion.
  double step_bound(const Vec12& q, const Vec12& dq) const;

 private:
  ContactParams params_;
};

// Closest distance between segment a0-a1 and segment b0-b1, q = [a0, a1, b0, b1].
double segment_distance(const Vec12& q);

}  // namespace yarnhom::yarn
