#pragma once
// Yarn-level fabric strips from a periodic pattern (docs/strip.md; supplement section 4.2 and
// Fig. 2, which follows Yuksel et al. 2012's stitch meshes):
//
// 0. The tile: the pattern relaxed at rest as the RVE relaxes it (rest_tile: relax_tile's
//    stress-free period by default, docs/rve.md section 6), in the reference tile's
//    coordinates; its lattice may be sheared (the first lattice vector is along x).
// 1. Tile the pattern over the strip's rectangle. Every yarn of a knit runs along the course
//    (x) and becomes one infinite ROW per tile row; a woven pattern has weft rows along x and
//    warp rows along y.
// 2. Keep the rows whose centre line lies inside the rectangle, each cut at the strip's two
//    ends: from its first to its last vertex inside the rectangle (vertices of a kept row
//    that bulge out between them stay: a loop is never cut). Everything else is dropped: the
//    pieces of outside rows that reach into the rectangle (the heads or legs of the next
//    course) are fragments too short to carry load.
// 3. Knits only: bind off. The next course above the top row and the one below the bottom
//    row are kept too, as boundary yarn: their loops catch the outermost rows' loops, which
//    would otherwise pull out (a cast-off / cast-on edge).
// 4. Join the rows into ONE yarn: rows sorted across the strip, traversed alternately in +
//    and - direction (serpentine), consecutive rows joined at the selvedge by a connector;
//    for woven patterns the wefts are joined first, then a corner connector leads to the
//    nearest warp, then the warps are joined at the top and bottom edges. A connector leaves
//    a row along the row's own continuation in the tiling (original geometry: it cannot
//    touch anything kept) until it is 2.5 radii beyond everything kept (its port), runs
//    straight out along the row's axis at the port's own height to its lane (a plane beyond
//    every port of that side), inside the lane straight or over or under everything to the
//    next row's port's across coordinate and height, and straight back in along that row's
//    continuation. Lanes are filled greedily from the inside so that no run comes near a
//    leg passing through its lane (docs/strip.md section 1).
// 5. Rest state: kept rows take the pattern's (rest lengths, curvatures, twists, reference
//    frames; a row traversed against the pattern's direction gets theta -> -theta and
//    k2 -> -k2, which leaves its energy unchanged). Boundary yarn (connectors and bind-off
//    rows) is stress-free at its initial shape: rest length, material curvatures and twist
//    measured on it; its moduli are connector_scale (1/200) of the yarn's.
//
// The result is one open yarn whose two free ends lie in the clamp bands of the stretch test.
#include <Eigen/Core>

#include "yarn/rod/pattern.hpp"
#include "yarn/rve/rest.hpp"
#include "yarn/strip/strip.hpp"

namespace yarnhom::yarn {

struct StripSpec {
  double width = 0.05;   // m, across the long axis
  double length = 0.10;  // m, along the long axis
  StripAxis axis = StripAxis::kCourse;
  double connector_scale = 1.0 / 200;
  bool bind_off = true;  // knits: boundary course above and below (step 3)
};

// What gets tiled: a pattern's geometry, twist angles and frames at rest (its rest lengths,
// curvatures and twists are the material's), and the lattice: vertex v of the copy in cell
// (i, j) sits at x_v + lattice (i, j), lattice(1, 0) = 0.
struct StripTile {
  Pattern pattern;
  Eigen::Matrix2d lattice = Eigen::Matrix2d::Identity();
};
// The pattern relaxed at rest by relax_tile (the stress-free tile unless opt.free_period is
// false), in its reference coordinates; throws what relax_tile throws.
StripTile rest_tile(const Pattern& raw, const Material& material, const RestOptions& opt = {});
// A pattern taken as it is (its stored geometry, rectangular period px x py).
StripTile as_tile(const Pattern& p);

// Throws std::invalid_argument naming the pattern when one of its yarns runs neither along x
// nor along y, or when the strip is narrower than a row or shorter than one period of a row.
Strip generate_strip(const StripTile& tile, const StripSpec& spec);

}  // namespace yarnhom::yarn
