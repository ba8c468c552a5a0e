#pragma once
// Where a configuration's energy sits (docs/rve.md, "Where the energy sits"): the energy of the
// RVE at strain s split over the base tile's vertices, so that two tiles (a generated pattern and
// a published one, say) can be compared stitch by stitch rather than by their totals only. Vertex
// v carries the stretch of its outgoing edge, the bend and twist of its joint, and half of every
// contact (and barrier) pair whose segment starts at v; the sums are evaluate()'s EnergyParts.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "yarn/rod/energy_parts.hpp"
#include "yarn/rve/rve.hpp"

namespace yarnhom::yarn {

struct VertexEnergy {
  int yarn = 0;              // index in topo().yarns
  Eigen::Vector3d x;         // position in the deformed base tile (m)
  Eigen::Vector3d pattern_x; // the pattern's stored position (m)
  EnergyParts e;             // J
  double curvature = 0;      // |(k1, k2)| / l of the joint now, 1/m
  double rest_curvature = 0; // |(K1, K2)| / l, 1/m
};

std::vector<VertexEnergy> energy_map(const RveProblem& rve, const Strain& s, const RveState& st);

// A tab-separated table, one row per vertex in yarn order (yarn after yarn, each from its first
// vertex): vertex, yarn, position and stored position in yarn radii, stretch, bend, twist, contact
// and barrier energy per area of the reference tile (J/m^2), curvature now and at rest (1/radius).
// Atomic (written next to `path`, then renamed).
void write_energy_map(const std::string& path, const RveProblem& rve, const std::vector<VertexEnergy>& map);

}  // namespace yarnhom::yarn
