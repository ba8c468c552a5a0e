// The energy per vertex (yarn/rve/energy_map.hpp): its sums are the RVE's energy parts, at rest
// and under a curved strain, and the table has one row per vertex.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "yarn/rod/generate.hpp"
#include "yarn/rve/energy_map.hpp"
#include "yarn/rve/rest.hpp"

using namespace yarnhom::yarn;

namespace {

void expect_sums(const RveProblem& rve, const Strain& s, const RveState& st) {
  EnergyParts parts;
  rve.evaluate(s, st, nullptr, nullptr, &parts);
  EnergyParts sum;
  for (const VertexEnergy& v : energy_map(rve, s, st)) {
    EXPECT_GE(v.e.stretch, 0);
    EXPECT_GE(v.e.bend, 0);
    EXPECT_GE(v.e.contact, 0);
    sum += v.e;
  }
  ASSERT_GT(parts.contact, 0) << "the check needs yarns in contact";
  ASSERT_GT(parts.stretch, 0);
  EXPECT_NEAR(sum.stretch, parts.stretch, 1e-10 * parts.stretch);
  EXPECT_NEAR(sum.bend, parts.bend, 1e-10 * parts.bend);
  EXPECT_NEAR(sum.twist, parts.twist, 1e-10 * std::abs(parts.twist) + 1e-300);
  EXPECT_NEAR(sum.contact, parts.contact, 1e-10 * parts.contact);
  EXPECT_NEAR(sum.barrier, parts.barrier, 1e-10 * std::abs(parts.barrier) + 1e-300);
}

}  // namespace

TEST(EnergyMap, SumsAreTheRveEnergyPartsAtRestAndUnderCurvedStrain) {
  const Pattern p = generate_stockinette({});
  const RestTile rt = relax_tile(p, Material{});
  ASSERT_TRUE(rt.report.converged);
  expect_sums(rt.rve, Strain::Zero(), rt.state);
  Strain s;
  s << 0.05, 0.02, -0.03, 40, -10, 25;  // the relaxed state moved by the shell map, unsolved
  expect_sums(rt.rve, s, rt.state);
}

TEST(EnergyMap, TableHasOneRowPerVertex) {
  const RveProblem rve(generate_stockinette({}), Material{});
  const RveState st = rve.initial_state();
  const auto path = std::filesystem::temp_directory_path() / "yarnhom_energy_map_test.tsv";
  write_energy_map(path.string(), rve, energy_map(rve, Strain::Zero(), st));
  std::ifstream in(path);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) ++lines;
  EXPECT_EQ(lines, rve.pattern().size() + 2);  // a comment, the header, the vertices
  std::filesystem::remove(path);
}
