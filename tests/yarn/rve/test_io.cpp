// Material files (errors name file and line), the state file round trip (warm start from a
// written state converges at once), and the OBJ tube mesh.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "yarn/rod/generate.hpp"
#include "yarn/rod/material.hpp"
#include "yarn/rve/state_io.hpp"

using namespace yarnhom::yarn;

TEST(Material, ParsesAndRefusesWithLineNumbers) {
  const Material m = parse_material("# comment\nyoung = 2e6\n\nslide_constraint = false\n", "m.txt");
  EXPECT_DOUBLE_EQ(m.young, 2e6);
  EXPECT_FALSE(m.slide_constraint);
  const Material back = parse_material(format_material(m), "again");
  EXPECT_DOUBLE_EQ(back.young, m.young);
  EXPECT_DOUBLE_EQ(back.shear, m.shear);
  auto msg = [](const std::string& text) {
    try {
      parse_material(text, "m.txt");
    } catch (const yarnhom::FileError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(msg("young = 1e6\nstiffness = 3\n").find("m.txt: line 2: unknown key 'stiffness'"), std::string::npos);
  EXPECT_NE(msg("young = soft\n").find("m.txt: line 1: value of 'young' is not a number"), std::string::npos);
  EXPECT_NE(msg("\nshear = -1\n").find("m.txt: line 2: 'shear' must be positive"), std::string::npos);
  EXPECT_NE(msg("young 1e6\n").find("m.txt: line 1: expected 'key = value'"), std::string::npos);
}

// The named materials: the files in yarn/rod/materials are the built-ins (the default is
// hylc-calibrated), a file path wins over a name, and anything else is refused naming the
// built-in names.
TEST(Material, NamedMaterialsAreTheFilesInTheRepository) {
  const std::string dir = std::string(YARNHOM_SOURCE_DIR) + "/yarn/rod/materials/";
  for (const std::string& name : builtin_material_names()) {
    const Material a = builtin_material(name), b = read_material(dir + name + ".txt");
    EXPECT_DOUBLE_EQ(a.young, b.young) << name;
    EXPECT_DOUBLE_EQ(a.shear, b.shear) << name;
    EXPECT_DOUBLE_EQ(a.density, b.density) << name;
    EXPECT_DOUBLE_EQ(a.contact_stiffness, b.contact_stiffness) << name;
    EXPECT_EQ(a.slide_constraint, b.slide_constraint) << name;
    EXPECT_DOUBLE_EQ(load_material(name).young, a.young);
  }
  EXPECT_DOUBLE_EQ(Material{}.young, builtin_material("hylc-calibrated").young);
  EXPECT_DOUBLE_EQ(builtin_material("yarnhom-2025").young, 1.0e6);
  EXPECT_DOUBLE_EQ(load_material(dir + "yarnhom-2025.txt").density, 1.2e3);
  try {
    load_material("cotton");
    FAIL() << "accepted an unknown material";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'cotton' is neither a file nor a built-in material (hylc-calibrated, yarnhom-2025)"),
              std::string::npos)
        << e.what();
  }
}

TEST(StateIo, WrittenStateWarmStartsAtItsOwnEquilibrium) {
  const RveProblem rve(generate_stockinette({}), Material{});
  RveState st = rve.initial_state();
  Strain s = Strain::Zero();
  s[0] = 0.2;
  s[3] = 50;
  const DensityResult r = energy_density(rve, s, st);
  ASSERT_TRUE(r.report.converged());
  const auto dir = std::filesystem::temp_directory_path();
  const std::string h5 = (dir / "yarnhom_test_state.h5").string(), obj = (dir / "yarnhom_test_state.obj").string();
  write_state(h5, rve, s, st, r);
  RveState back = read_state(h5, rve);
  const SolveReport again = solve(rve, s, back);
  EXPECT_TRUE(again.converged());
  EXPECT_EQ(again.iterations, 0);
  EXPECT_NEAR(again.energy, r.report.energy, 1e-14 * r.report.energy);
  // A state of another pattern is refused, naming the dataset.
  const RveProblem other(generate_woven({}), Material{});
  try {
    read_state(h5, other);
    FAIL();
  } catch (const yarnhom::FileError& e) {
    EXPECT_NE(std::string(e.what()).find("q"), std::string::npos);
  }
  write_obj(obj, rve, s, st, 6);
  std::ifstream in(obj);
  int v = 0, f = 0;
  for (std::string line; std::getline(in, line);) {
    v += line.rfind("v ", 0) == 0;
    f += line.rfind("f ", 0) == 0;
  }
  const int n = rve.pattern().size();
  EXPECT_EQ(v, 6 * (n + 1));  // one yarn: n + 1 rings (closed on the first vertex's image)
  EXPECT_EQ(f, 6 * n);
  std::filesystem::remove(h5);
  std::filesystem::remove(obj);
}
