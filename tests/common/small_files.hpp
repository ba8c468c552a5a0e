#pragma once
// Small valid input files of every kind the program reads, made in the test (never the
// patterns of ../shared): a .pyp pattern, a dataset, a model and a baked file. The hardening
// tests damage copies of them.
#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "bake/bake_table.hpp"
#include "core/baked.hpp"
#include "core/dataset.hpp"
#include "core/model.hpp"
#include "produce/synthetic.hpp"
#include "tests/common/random_net.hpp"
#include "yarn/rod/generate.hpp"
#include "yarn/rod/pattern.hpp"

namespace yarnhom::test {

// A fresh folder per test, removed at the end.
struct TempDir {
  std::filesystem::path dir;
  explicit TempDir(const std::string& tag) {
    dir = std::filesystem::temp_directory_path() /
          ("yarnhom_" + tag + "_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~TempDir() { std::filesystem::remove_all(dir); }
  std::string operator/(const std::string& f) const { return (dir / f).string(); }
};

// The tiny generated stockinette (16 vertices, 0.1 mm yarn) as a .pyp file with every block.
inline void write_small_pattern(const std::string& path) { yarn::write_pyp(path, yarn::generate_stockinette({})); }

// The same with a rest curvature on every vertex (0.05, 0): a pattern whose loops are not all
// straight at rest, which strip accepts at any size (yarn/strip/strip_run.cpp). For tests of
// option checks only: it is no pattern's real rest state.
inline void write_curved_pattern(const std::string& path) {
  yarn::Pattern p = yarn::generate_stockinette({});
  for (auto& k : p.rest_kappa) k = Eigen::Vector2d(0.05, 0.0);
  yarn::write_pyp(path, p);
}

// The synthetic quick dataset restricted to terms 0 and 02 (21 and 81 samples).
inline Dataset small_dataset() {
  Dataset ds = make_synthetic_dataset("quick");
  Dataset out = ds;
  out.terms.clear();
  for (const TermData& t : ds.terms)
    if (t.term.name == "0" || t.term.name == "02") out.terms.push_back(t);
  return out;
}

// Networks 0 and 02 with random weights over the dataset's boxes, a short history.
inline Model small_model(const std::string& dataset_name) {
  Model m;
  m.dataset = dataset_name;
  m.seed = 7;
  for (const char* name : {"0", "02"}) {
    ModelNetwork n;
    n.term = term_by_name(name);
    const int d = n.term.dim();
    for (int k = 0; k < d; ++k) {
      n.lower.push_back(-0.2);
      n.upper.push_back(1.0);
      n.norm.center.push_back(0.4);
      n.norm.halfwidth.push_back(0.6);
    }
    n.desc.input_dim = d;
    n.desc.hidden = {4, 5};
    n.params = random_params<float>(n.desc, d == 1 ? 11u : 12u);
    n.norm.out_mean = 1.5;
    n.norm.out_std = 2.0;
    n.epochs = 3;
    for (int e = 0; e < 3; ++e)
      for (auto* v : {&n.history.train_loss, &n.history.val_loss, &n.history.lr, &n.history.loss_z,
                      &n.history.loss_f, &n.history.loss_c, &n.history.loss_s})
        v->push_back(1.0 / (e + 1));
    m.networks.push_back(std::move(n));
  }
  return m;
}

// dataset.h5, model.h5 (naming dataset.h5) and baked.h5 in dir.
struct SmallFiles {
  std::string pattern, dataset, model, baked;
};
inline SmallFiles write_small_files(const TempDir& d) {
  SmallFiles f{d / "pattern.pyp", d / "dataset.h5", d / "model.h5", d / "baked.h5"};
  write_small_pattern(f.pattern);
  const Dataset ds = small_dataset();
  write_dataset(f.dataset, ds);
  const Model m = small_model(f.dataset);
  write_model(f.model, m);
  write_baked(f.baked, bake_model(m, f.model, 20, 8, ds.psi0, true));
  return f;
}

}  // namespace yarnhom::test
