// Dataset and model files: round trips, and every kind of bad input refused with a message
// that names the file, the object and the problem.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/dataset.hpp"
#include "core/error.hpp"
#include "core/h5.hpp"
#include "core/model.hpp"
#include "produce/synthetic.hpp"

using namespace yarnhom;
namespace fs = std::filesystem;

namespace {

struct TempDir {
  fs::path dir;
  TempDir() {
    dir = fs::temp_directory_path() / ("yarnhom_test_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir);
  }
  ~TempDir() { fs::remove_all(dir); }
  std::string operator/(const std::string& f) const { return (dir / f).string(); }
};

// Writes a dataset file by hand through the HDF5 layer (bypassing write_dataset's checks),
// with one term "0" whose pieces can be spoiled.
void write_raw_dataset(const std::string& path, int n, int strain_cols, double bad_value,
                       bool with_rest = true, const std::string& term = "0") {
  auto root = h5::create_file(path);
  root.set_attr("format", kDatasetFormat);
  root.set_attr("version", kDatasetVersion);
  if (with_rest) root.create_group("rest").set_attr("psi0", 0.0);
  auto g = root.create_group("terms/" + term);
  std::vector<double> s(n * strain_cols), e(n, 1.0), gr(n, 0.5), raw(n, 1.0);
  for (int i = 0; i < n * strain_cols; ++i) s[i] = 0.01 * i;
  e[n - 1] = bad_value;
  g.write("strain", s, {hsize_t(n), hsize_t(strain_cols)});
  g.write("energy", e, {hsize_t(n)});
  g.write("gradient", gr, {hsize_t(n), 1});
  g.write("raw", raw, {hsize_t(n)});
  g.set_attr("indices", std::vector<int>{0});
  g.set_attr("lower", std::vector<double>{-0.2});
  g.set_attr("upper", std::vector<double>{1.0});
}

void expect_refused(const std::string& path, const std::string& object, const std::string& problem) {
  try {
    read_dataset(path);
    FAIL() << "accepted a bad dataset: expected '" << problem << "'";
  } catch (const FileError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(object), std::string::npos) << msg;
    EXPECT_NE(msg.find(problem), std::string::npos) << msg;
  }
}

}  // namespace

TEST(DatasetFile, RoundTrip) {
  TempDir t;
  Dataset a = make_synthetic_dataset("quick");
  write_dataset(t / "d.h5", a);
  Dataset b = read_dataset(t / "d.h5");
  EXPECT_EQ(b.source, "synthetic");
  EXPECT_EQ(b.note, a.note);
  ASSERT_EQ(b.terms.size(), 14u);
  for (size_t i = 0; i < a.terms.size(); ++i) {
    EXPECT_EQ(b.terms[i].term.name, a.terms[i].term.name);
    EXPECT_EQ(b.terms[i].strain, a.terms[i].strain);
    EXPECT_EQ(b.terms[i].energy, a.terms[i].energy);
    EXPECT_EQ(b.terms[i].gradient, a.terms[i].gradient);
    EXPECT_EQ(b.terms[i].raw, a.terms[i].raw);
    EXPECT_EQ(b.terms[i].lower, a.terms[i].lower);
  }
  EXPECT_FALSE(fs::exists(t / "d.h5.partial-" + std::to_string(::getpid())));
}

// The rest-state additions (periods, rest gradient, areal density) are optional: a file
// without them (every file written before them, and synthetic data) reads with the fields
// empty / NaN; a file with them round-trips; a wrong size or a non-positive density is
// refused naming the attribute.
TEST(DatasetFile, RestAdditionsAreOptionalAndRoundTrip) {
  TempDir t;
  write_raw_dataset(t / "old.h5", 3, 1, 1.0);  // as an old producer wrote it
  const Dataset old = read_dataset(t / "old.h5");
  EXPECT_TRUE(old.lattice_original.empty() && old.lattice_relaxed.empty() && old.grad0.empty());
  EXPECT_TRUE(std::isnan(old.areal_density));
  Dataset a = make_synthetic_dataset("quick");
  write_dataset(t / "plain.h5", a);
  EXPECT_FALSE(h5::open_file(t / "plain.h5").has_attr("areal_density"));
  a.lattice_original = {0.015, 0, 0, 0.008};
  a.lattice_relaxed = {0.0138, 0, 4.6e-5, 0.0084};
  a.grad0 = {1e-9, -2e-9, 3e-9, 0.0275, 0.0002, -0.0227};
  a.areal_density = 0.34;
  write_dataset(t / "d.h5", a);
  const Dataset b = read_dataset(t / "d.h5");
  EXPECT_EQ(b.lattice_original, a.lattice_original);
  EXPECT_EQ(b.lattice_relaxed, a.lattice_relaxed);
  EXPECT_EQ(b.grad0, a.grad0);
  EXPECT_EQ(b.areal_density, 0.34);
  a.grad0.pop_back();
  EXPECT_THROW(write_dataset(t / "e.h5", a), FileError);
  a.grad0.push_back(0);
  // The rest Hessian: 36 entries, symmetric; round trip, and a non-symmetric one is refused
  // with the object and the entries named.
  EXPECT_TRUE(b.rest_hessian.empty());
  a.rest_hessian.assign(36, 0.0);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) a.rest_hessian[i * 6 + j] = (i == j ? 10.0 + i : 0.1 * (i + j));
  write_dataset(t / "h.h5", a);
  EXPECT_EQ(read_dataset(t / "h.h5").rest_hessian, a.rest_hessian);
  a.rest_hessian[1] += 1e-3;
  try {
    write_dataset(t / "e.h5", a);
    FAIL() << "accepted a non-symmetric rest Hessian";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("/rest"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not symmetric"), std::string::npos) << e.what();
  }
  a.rest_hessian.resize(35);
  EXPECT_THROW(write_dataset(t / "e.h5", a), FileError);
  a.rest_hessian.clear();
  a.areal_density = -1;
  try {
    write_dataset(t / "e.h5", a);
    FAIL() << "accepted a negative areal density";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("areal_density"), std::string::npos) << e.what();
  }
}

TEST(DatasetFile, MissingFile) { expect_refused("/nonexistent/d.h5", "", "no such file"); }

TEST(DatasetFile, NotHdf5) {
  TempDir t;
  std::ofstream(t / "x.h5") << "this is text, not HDF5\n";
  expect_refused(t / "x.h5", "", "not an HDF5 file");
}

TEST(DatasetFile, Truncated) {
  TempDir t;
  write_dataset(t / "d.h5", make_synthetic_dataset("quick"));
  fs::resize_file(t / "d.h5", fs::file_size(t / "d.h5") / 2);
  EXPECT_THROW(read_dataset(t / "d.h5"), FileError);
}

TEST(DatasetFile, MissingGroup) {
  TempDir t;
  write_raw_dataset(t / "d.h5", 5, 1, 1.0, /*with_rest=*/false);
  expect_refused(t / "d.h5", "/rest", "missing group");
}

TEST(DatasetFile, WrongShape) {
  TempDir t;
  write_raw_dataset(t / "d.h5", 5, 3, 1.0);
  expect_refused(t / "d.h5", "/terms/0/strain", "wrong shape");
}

TEST(DatasetFile, NonFinite) {
  TempDir t;
  write_raw_dataset(t / "d.h5", 5, 1, std::nan(""));
  expect_refused(t / "d.h5", "/terms/0/energy", "non-finite");
}

TEST(DatasetFile, TooFewPoints) {
  TempDir t;
  write_raw_dataset(t / "d.h5", 1, 1, 1.0);
  expect_refused(t / "d.h5", "/terms/0", "fewer than 2 samples");
}

TEST(DatasetFile, UnknownTerm) {
  TempDir t;
  write_raw_dataset(t / "d.h5", 5, 1, 1.0, true, "04");
  expect_refused(t / "d.h5", "/terms/04", "unknown term");
}

TEST(DatasetFile, WrongFormatTag) {
  TempDir t;
  h5::create_file(t / "m.h5").set_attr("format", "something-else");
  expect_refused(t / "m.h5", "/", "not a yarnhom dataset");
}

TEST(DatasetFile, FailedWriteKeepsTheOldFile) {
  TempDir t;
  write_dataset(t / "d.h5", make_synthetic_dataset("quick"));
  const auto before = fs::file_size(t / "d.h5");
  Dataset bad = make_synthetic_dataset("quick");
  bad.terms[0].energy[0] = INFINITY;
  EXPECT_THROW(write_dataset(t / "d.h5", bad), FileError);
  EXPECT_EQ(fs::file_size(t / "d.h5"), before);
  EXPECT_NO_THROW(read_dataset(t / "d.h5"));
}

TEST(ModelFile, RoundTrip) {
  TempDir t;
  Model m;
  m.dataset = "some.h5";
  m.seed = 42;
  for (const char* name : {"0", "02"}) {
    ModelNetwork n;
    n.term = term_by_name(name);
    n.desc.input_dim = n.term.dim();
    n.params.resize(n.desc.num_params());
    for (size_t i = 0; i < n.params.size(); ++i) n.params[i] = 0.001f * float(i) - 0.3f;
    for (int k = 0; k < n.term.dim(); ++k) {
      n.lower.push_back(-1 - k);
      n.upper.push_back(2 + k);
      n.norm.center.push_back(0.5);
      n.norm.halfwidth.push_back(1.5 + k);
    }
    n.norm.out_mean = 0.25;
    n.norm.out_std = 3.5;
    n.epochs = 7;
    n.history.train_loss = {3, 2, 1};
    n.history.val_loss = {4, 3, 2};
    n.history.lr = {1e-3, 1e-3, 5e-4};
    n.history.loss_z = n.history.loss_f = n.history.loss_c = n.history.loss_s = {1, 1, 1};
    m.networks.push_back(n);
  }
  write_model(t / "m.h5", m);
  Model r = read_model(t / "m.h5");
  EXPECT_EQ(r.dataset, "some.h5");
  EXPECT_EQ(r.seed, 42u);
  EXPECT_TRUE(std::isnan(r.areal_density)) << "absent: unknown";
  m.areal_density = 0.33;
  write_model(t / "m2.h5", m);
  EXPECT_EQ(read_model(t / "m2.h5").areal_density, 0.33);
  ASSERT_EQ(r.networks.size(), 2u);
  for (size_t j = 0; j < 2; ++j) {
    EXPECT_EQ(r.networks[j].params, m.networks[j].params);
    EXPECT_EQ(r.networks[j].norm.halfwidth, m.networks[j].norm.halfwidth);
    EXPECT_EQ(r.networks[j].norm.out_std, 3.5);
    EXPECT_EQ(r.networks[j].history.lr, m.networks[j].history.lr);
    EXPECT_EQ(r.networks[j].desc.hidden, (std::vector<int>{16, 32, 16}));
    EXPECT_EQ(r.networks[j].epochs, 7);
  }
  // Layer shapes as the spec says: layer0/W is [16, d].
  auto g = h5::open_file(t / "m.h5").group("networks/02/layer0");
  EXPECT_EQ(g.read_float("W").dims, (std::vector<hsize_t>{16, 2}));
}

TEST(ModelFile, RefusesADataset) {
  TempDir t;
  write_dataset(t / "d.h5", make_synthetic_dataset("quick"));
  try {
    read_model(t / "d.h5");
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("not a yarnhom model"), std::string::npos);
  }
}

TEST(SyntheticEnergy, GradientMatchesFiniteDifferences) {
  const double s[6] = {0.3, -0.2, 0.5, 80, 10, -120};
  double g[6];
  synthetic_psi(s, g);
  for (int i = 0; i < 6; ++i) {
    const double h = i < 3 ? 1e-6 : 1e-3;
    double sp[6], sm[6];
    std::copy(s, s + 6, sp);
    std::copy(s, s + 6, sm);
    sp[i] += h;
    sm[i] -= h;
    const double fd = (synthetic_psi(sp) - synthetic_psi(sm)) / (2 * h);
    EXPECT_NEAR(g[i], fd, 1e-8 * (1 + std::abs(fd))) << i;
  }
}

TEST(SyntheticDataset, TwoDimensionalResidualVanishesOnTheAxes) {
  Dataset ds = make_synthetic_dataset("paper");
  const TermData* t = ds.find("02");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->n, 31 * 31);
  EXPECT_EQ(ds.find("0")->n, 100);
  int on_axes = 0;
  for (int i = 0; i < t->n; ++i)
    if (t->strain[2 * i] == 0.0 || t->strain[2 * i + 1] == 0.0) {
      EXPECT_NEAR(t->energy[i], 0.0, 1e-15);
      ++on_axes;
    }
  EXPECT_EQ(on_axes, 61);  // the grid contains 0 on both axes
}
