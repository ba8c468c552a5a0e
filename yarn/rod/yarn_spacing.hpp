#pragma once
// Distances between the yarn segments of a stored pattern, and a step that spaces a generated
// sketch's yarns to contact distance without changing how they pass each other.
#include "yarn/rod/pattern.hpp"

namespace yarnhom::yarn {

// The closest distance (m) between two segments of the stored geometry, over the periodic
// images, that are not within `skip` edges of each other along one yarn (a segment and its
// neighbours always touch). +inf where no pair comes within `reach`.
double closest_segment_distance(const Pattern& p, int skip = 4, double reach = 0);

// How many such segment pairs (each counted once) are closer than `distance` (m).
int segment_pairs_closer_than(const Pattern& p, double distance, int skip = 4);

// Pushes apart, for `iterations` rounds, every such pair closer than `distance` (m): each
// round moves the two segments' ends along the line of their closest points by half the
// shortfall each (shared by the ends as the closest points divide the segments), the moves
// averaged along the yarn over its neighbours, plus `smoothing` r^2 / (e_a e_b) (at most 0.45)
// times the move of each vertex to the midpoint of its neighbours, e_a and e_b its edges' lengths
// (umbrella smoothing scaled so that each round is the same step of curve-shortening flow,
// whatever the sampling; it also shortens the yarn).
// No vertex moves more than 0.45 of the round's closest distance, so no two segments pass
// through each other: the yarns keep the sketch's crossings (which yarn passes in front).
// Vertices that leave the tile are wrapped back (their edges' offsets follow). Leaves the rest
// state alone (call set_rest_to_shape after). Throws std::invalid_argument unless distance > 0
// and 0 <= smoothing < 0.5.
void space_yarns(Pattern& p, double distance, double smoothing, int iterations = 200);

}  // namespace yarnhom::yarn
