// The baked file: written atomically, read back identically, and bad files refused with a
// message naming the file, the object and the problem.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>

#include <filesystem>

#include "bake/bake_table.hpp"
#include "material/material.hpp"
#include "core/baked.hpp"
#include "core/error.hpp"
#include "core/h5.hpp"
#include "tests/common/bake_test_util.hpp"

using namespace yarnhom;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir() {
  fs::path d = fs::temp_directory_path() / ("yarnhom_bake_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

BakedModel small_model() {
  Model m;
  m.dataset = "data.h5";
  m.networks.push_back(test::random_model_network("2", {-0.2}, {1.0}, 51));
  m.networks.push_back(test::random_model_network("03", {-0.2, -200.0}, {1.0, 200.0}, 52));
  return bake_model(m, "model.h5", 50, 12, 0.125, true);
}

}  // namespace

TEST(BakedFile, RoundTrip) {
  const fs::path p = temp_dir() / "baked.h5";
  BakedModel m = small_model();
  write_baked(p.string(), m);
  int entries = 0;  // nothing left beside it (no temporary file)
  for (const auto& e : fs::directory_iterator(p.parent_path())) entries += e.path() != p;
  EXPECT_EQ(entries, 0);
  BakedModel r = read_baked(p.string());
  EXPECT_EQ(r.model, "model.h5");
  EXPECT_EQ(r.dataset, "data.h5");
  EXPECT_DOUBLE_EQ(r.psi0, 0.125);
  EXPECT_TRUE(r.psi0_known);
  EXPECT_TRUE(std::isnan(r.areal_density)) << "absent (the model did not know it): unknown";
  ASSERT_EQ(r.tables.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    const BakedTable &a = m.tables[k], &b = r.tables[k];
    EXPECT_EQ(a.term.name, b.term.name);
    EXPECT_EQ(a.knots, b.knots);
    EXPECT_EQ(a.f, b.f);
    EXPECT_EQ(a.f_x, b.f_x);
    EXPECT_EQ(a.f_y, b.f_y);
    EXPECT_EQ(a.f_xy, b.f_xy);
    EXPECT_EQ(a.safeguard_lower, b.safeguard_lower);
    EXPECT_EQ(a.edges, b.edges);
    EXPECT_EQ(a.corners, b.corners);
    EXPECT_EQ(a.norm.halfwidth, b.norm.halfwidth);
    EXPECT_EQ(a.desc.hidden, b.desc.hidden);
    EXPECT_NO_THROW(make_baked_term(b, p.string()));
  }
  // The areal density round-trips and reaches the full material (the simulator's gravity).
  m.areal_density = 0.3318;
  write_baked(p.string(), m);
  EXPECT_EQ(read_baked(p.string()).areal_density, 0.3318);
  EXPECT_EQ(make_baked_material(read_baked(p.string())).areal_density, 0.3318);
  fs::remove_all(p.parent_path());
}

TEST(BakedFile, RefusesBadFiles) {
  const fs::path dir = temp_dir();
  // Not HDF5 at all.
  const fs::path junk = dir / "junk.h5";
  { FILE* f = std::fopen(junk.c_str(), "w"); std::fputs("hello", f); std::fclose(f); }
  EXPECT_THROW(read_baked(junk.string()), FileError);
  // A model file is not a baked file.
  const fs::path other = dir / "other.h5";
  { h5::Node root = h5::create_file(other.string()); root.set_attr("format", "yarnhom-model"); }
  try {
    read_baked(other.string());
    FAIL();
  } catch (const FileError& e) {
    EXPECT_EQ(e.file(), other.string());
    EXPECT_NE(std::string(e.what()).find("not a yarnhom baked file"), std::string::npos);
  }
  // A table of the wrong shape: names the dataset.
  BakedModel m = small_model();
  m.tables[1].f.pop_back();
  try {
    write_baked((dir / "bad.h5").string(), m);
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("/tables/03/f"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "bad.h5"));
  // Non-finite knot data.
  m = small_model();
  m.tables[0].f_x[3] = std::nan("");
  EXPECT_THROW(write_baked((dir / "bad.h5").string(), m), FileError);
  fs::remove_all(dir);
}
