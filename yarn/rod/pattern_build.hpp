#pragma once
// Building blocks of the pattern generators (generate.hpp): closed yarns from a curve over one
// period, sampled at equal arc length, and a rest state taken from the generated shape.
#include <Eigen/Core>
#include <functional>
#include <vector>

#include "yarn/rod/pattern.hpp"

namespace yarnhom::yarn {

// Appends one closed yarn given its unwrapped polyline over exactly one period (the point after
// the last is the first shifted by `period_shift` tiles), wrapping vertices into the tile
// [-px/2, px/2) x [-py/2, py/2) and recording edge offsets. Sets theta = 0 for its vertices.
void add_yarn(Pattern& pat, const std::vector<Eigen::Vector3d>& pts, Eigen::Vector2i period_shift);

// n points at equal arc length along the curve c(t), t in [0, 1), where c(1) is c(0) moved by
// one period (the curve is measured on a fine polyline of 64 n pieces).
std::vector<Eigen::Vector3d> sample_equal_arc(const std::function<Eigen::Vector3d(double)>& c, int n);

// The rest state of the stored shape: rest lengths = edge lengths, reference frames by parallel
// transport (complete_rest_state), rest curvatures and twists = the shape's (theta as stored).
// The yarn is then stress free as generated, like yarn set by knitting or weaving: what the
// relaxation at rest leaves is the contacts' push and the bending it causes.
void set_rest_to_shape(Pattern& p);

// Total rest length of the tile's yarn (m).
double total_rest_length(const Pattern& p);

}  // namespace yarnhom::yarn
