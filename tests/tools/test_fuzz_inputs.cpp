// Issue 11: a seeded fuzz test of every input kind. A few hundred mutants of a .pyp pattern and
// of each HDF5 file (dataset, model, baked), each read by the library and then used (an RVE
// energy and a few Newton iterations; a network or table evaluation), must either pass or be
// refused with an exception whose message names the file: never a crash, never a hang, never a
// message that names nothing (std::bad_alloc, "vector::_M_default_append", ...). A sample of
// the mutants also goes through the program itself.
//
// The readers run in a forked child per kind with an alarm per mutant, so that a crash or a
// hang is reported with the kind, the mutant's number and its file (kept for reproduction)
// instead of taking the test runner down. The regression corpus of the issue (twist angle
// 1e15, radius 1 m and 1e-30 m, edge index 1e300, a 2^40-entry history, 2^28 energies, a
// corrupt knot count, out_std = 0, a network under a non-term name, psi0 = NaN, h5py's
// variable-length strings) comes first in each kind, then the random mutants.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

#include "material/baked_eval.hpp"
#include "material/material.hpp"
#include "core/baked.hpp"
#include "core/dataset.hpp"
#include "core/error.hpp"
#include "core/jet_layout.hpp"
#include "core/model.hpp"
#include "cpu/network_eval.hpp"
#include "tests/common/fuzz_kinds.hpp"
#include "tests/common/h5_edit.hpp"
#include "tests/common/run_cli.hpp"
#include "tests/common/small_files.hpp"
#include "yarn/rve/newton.hpp"
#include "yarn/rve/rve.hpp"

namespace fs = std::filesystem;
namespace h5e = yarnhom::test::h5edit;
using namespace yarnhom;
using yarnhom::test::Kind;
using yarnhom::test::run_kind;

namespace {

using Rng = std::mt19937_64;

int pick(Rng& rng, int n) { return int(std::uniform_int_distribution<int>(0, n - 1)(rng)); }

const std::vector<std::string> kHostileNumbers = {
    "0", "-0", "-1", "1e300", "-1e300", "1e-300", "nan", "inf", "-inf", "1e15", "2147483648", "-2147483649",
    "0.5", "1e-30", "1", "99999999999", "x", "1e", "--1", "0x10", "1e308", "-7"};
const std::vector<double> kHostileValues = {0.0, -0.0, -1.0, 1e300, -1e300, 1e-300, NAN, INFINITY, -INFINITY,
                                            1e15, 2147483648.0, -2147483649.0, 0.5, 1e-30, 4294967296.0, 3.0};

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

// ---------- .pyp mutants (text) ----------

std::vector<std::string> lines_of(const std::string& t) {
  std::vector<std::string> v;
  std::istringstream in(t);
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}
std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (auto& l : v) s += l + "\n";
  return s;
}

// The numeric tokens' positions in the text.
std::vector<std::pair<size_t, size_t>> number_tokens(const std::string& t) {
  std::vector<std::pair<size_t, size_t>> out;
  size_t i = 0;
  bool comment = false, header = false;
  while (i < t.size()) {
    const char c = t[i];
    if (c == '\n') comment = header = false;
    if (c == '#') comment = true;
    if (c == '*' && (i == 0 || t[i - 1] == '\n')) header = true;
    if (!comment && !header && (std::isdigit((unsigned char)c) || c == '-' || c == '.')) {
      size_t j = i;
      while (j < t.size() && !std::isspace((unsigned char)t[j])) ++j;
      out.push_back({i, j - i});
      i = j;
      continue;
    }
    ++i;
  }
  return out;
}

std::string mutate_text(std::string t, Rng& rng) {
  const int ops = 1 + pick(rng, 3);
  for (int k = 0; k < ops; ++k) {
    auto lines = lines_of(t);
    switch (pick(rng, 10)) {
      case 0:
      case 1:
      case 2: {  // a number replaced by a hostile one
        auto toks = number_tokens(t);
        if (toks.empty()) break;
        auto [pos, len] = toks[pick(rng, int(toks.size()))];
        t.replace(pos, len, kHostileNumbers[pick(rng, int(kHostileNumbers.size()))]);
        break;
      }
      case 3: {  // a number scaled
        auto toks = number_tokens(t);
        if (toks.empty()) break;
        auto [pos, len] = toks[pick(rng, int(toks.size()))];
        const double v = std::strtod(t.substr(pos, len).c_str(), nullptr);
        const double f[] = {1e3, -1, 1e-3, 1e6, 2};
        char buf[40];
        std::snprintf(buf, sizeof buf, "%.17g", v * f[pick(rng, 5)]);
        t.replace(pos, len, buf);
        break;
      }
      case 4:  // a line deleted
        if (!lines.empty()) lines.erase(lines.begin() + pick(rng, int(lines.size())));
        t = join(lines);
        break;
      case 5:  // a line duplicated
        if (!lines.empty()) {
          const int i = pick(rng, int(lines.size()));
          lines.insert(lines.begin() + i, lines[i]);
        }
        t = join(lines);
        break;
      case 6:  // two lines swapped
        if (lines.size() > 1) std::swap(lines[pick(rng, int(lines.size()))], lines[pick(rng, int(lines.size()))]);
        t = join(lines);
        break;
      case 7:  // truncated
        t = t.substr(0, pick(rng, int(t.size()) + 1));
        break;
      case 8: {  // bytes inserted, binary ones included
        const int n = 1 + pick(rng, 8);
        std::string junk;
        for (int i = 0; i < n; ++i) junk += char(pick(rng, 256));
        t.insert(size_t(pick(rng, int(t.size()) + 1)), junk);
        break;
      }
      case 9: {  // a token added to or removed from a line
        if (lines.empty()) break;
        auto& l = lines[pick(rng, int(lines.size()))];
        if (pick(rng, 2)) l += " " + kHostileNumbers[pick(rng, int(kHostileNumbers.size()))];
        else if (auto sp = l.rfind(' '); sp != std::string::npos) l = l.substr(0, sp);
        t = join(lines);
        break;
      }
    }
  }
  return t;
}

// ---------- HDF5 mutants (structured, through the C API) ----------

struct H5Map {
  std::vector<std::string> groups, datasets;
  std::vector<std::pair<std::string, std::string>> attrs;  // object, name
};

H5Map map_file(const std::string& path) {
  H5Map m;
  h5e::File f(path);
  struct Ctx {
    H5Map* m;
    hid_t file;
  } ctx{&m, f.id()};
  H5Ovisit(
      f.id(), H5_INDEX_NAME, H5_ITER_INC,
      [](hid_t, const char* name, const H5O_info_t* info, void* p) -> herr_t {
        auto* c = static_cast<Ctx*>(p);
        const std::string obj = std::string(name) == "." ? "/" : "/" + std::string(name);
        if (info->type == H5O_TYPE_GROUP) c->m->groups.push_back(obj);
        if (info->type == H5O_TYPE_DATASET) c->m->datasets.push_back(obj);
        hid_t o = H5Oopen(c->file, obj.c_str(), H5P_DEFAULT);
        struct A {
          Ctx* c;
          std::string obj;
        } a{c, obj};
        H5Aiterate2(
            o, H5_INDEX_NAME, H5_ITER_INC, nullptr,
            [](hid_t, const char* an, const H5A_info_t*, void* q) -> herr_t {
              auto* a = static_cast<A*>(q);
              a->c->m->attrs.push_back({a->obj, an});
              return 0;
            },
            &a);
        H5Oclose(o);
        return 0;
      },
      &ctx);
  return m;
}

void mutate_h5(const std::string& path, Rng& rng) {
  const H5Map m = map_file(path);
  const int ops = 1 + pick(rng, 2);
  for (int k = 0; k < ops; ++k) {
    const int op = pick(rng, 12);
    if (op == 11) {  // truncated (byte-level; the library must say so, not crash)
      const auto size = fs::file_size(path);
      fs::resize_file(path, size_t(pick(rng, int(size))));
      return;
    }
    h5e::File f(path);
    if (op <= 4 && !m.datasets.empty()) {
      const std::string ds = m.datasets[pick(rng, int(m.datasets.size()))];
      switch (op) {
        case 0: {  // huge declared, nothing stored
          std::vector<hsize_t> dims(1 + pick(rng, 3));
          for (auto& d : dims) d = hsize_t(1) << pick(rng, 41);
          h5e::put_dataset(f, ds, dims);
          break;
        }
        case 1: {  // another small shape
          std::vector<hsize_t> dims(1 + pick(rng, 2));
          size_t n = 1;
          for (auto& d : dims) n *= (d = hsize_t(pick(rng, 12)));
          std::vector<double> v(n, 0.25);
          h5e::put_dataset(f, ds, dims, &v);
          break;
        }
        case 2: {  // same shape, hostile values
          hid_t d = H5Dopen2(f.id(), ds.c_str(), H5P_DEFAULT);
          hid_t sp = H5Dget_space(d);
          const hssize_t n = H5Sget_simple_extent_npoints(sp);
          std::vector<hsize_t> dims(H5Sget_simple_extent_ndims(sp));
          H5Sget_simple_extent_dims(sp, dims.data(), nullptr);
          H5Sclose(sp);
          H5Dclose(d);
          if (n <= 0 || n > 1000000) break;
          std::vector<double> v(n, 0.5);
          for (int i = 0; i < 1 + pick(rng, 3); ++i) v[pick(rng, int(n))] = kHostileValues[pick(rng, int(kHostileValues.size()))];
          h5e::put_dataset(f, ds, dims, &v);
          break;
        }
        case 3: {  // another type
          std::vector<double> v = {1, 2, 3};
          h5e::put_dataset(f, ds, {3}, &v, pick(rng, 2) ? H5T_STD_I8LE : H5T_IEEE_F32LE);
          break;
        }
        case 4:
          h5e::remove(f, ds);
          break;
      }
    } else if (op <= 9 && !m.attrs.empty()) {
      const auto& [obj, name] = m.attrs[pick(rng, int(m.attrs.size()))];
      switch (op) {
        case 5:
          h5e::remove_attr(f, obj, name);
          break;
        case 6: {
          std::vector<double> v(pick(rng, 5));
          for (auto& x : v) x = kHostileValues[pick(rng, int(kHostileValues.size()))];
          if (v.empty()) v.push_back(NAN);
          h5e::set_attr(f, obj, name, v, pick(rng, 2) ? H5T_IEEE_F64LE : H5T_STD_I64LE);
          break;
        }
        case 7:
          h5e::set_attr_vlen_utf8(f, obj, name, pick(rng, 2) ? "02" : "\xff\xfe weird");
          break;
        case 8:
          h5e::set_attr_fixed(f, obj, name, pick(rng, 2) ? "sigmoid" : "", hsize_t(1 + pick(rng, 3)));
          break;
        case 9: {
          std::vector<double> v(1 + pick(rng, 3), double(int64_t(1) << 40));
          h5e::set_attr(f, obj, name, v, H5T_STD_I64LE);
          break;
        }
      }
    } else if (!m.groups.empty()) {  // groups: renamed, removed, or a stranger added
      const std::string g = m.groups[pick(rng, int(m.groups.size()))];
      if (g == "/") continue;
      const int c = pick(rng, 3);
      if (c == 0) h5e::rename(f, g, g.substr(0, g.rfind('/') + 1) + (pick(rng, 2) ? "zz" : "04"));
      else if (c == 1) h5e::remove(f, g);
      else H5Gclose(H5Gcreate2(f.id(), (g + "/extra").c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    }
  }
}

// ---------- readers: read, then use ----------

void use_pattern(const std::string& path) {
  const yarn::Pattern p = yarn::read_pyp(path);
  const yarn::RveProblem rve(p, yarn::Material{});
  yarn::RveState st = rve.initial_state();
  Eigen::VectorXd g;
  std::vector<Eigen::Triplet<double>> h;
  rve.evaluate(yarn::Strain::Zero(), st, &g, &h);
  yarn::SolveOptions opt;
  opt.max_iterations = 3;
  opt.max_seconds = 2;
  yarn::solve(rve, yarn::Strain::Zero(), st, opt);
}

void use_dataset(const std::string& path) { read_dataset(path); }

void use_model(const std::string& path) {
  if (is_baked_file(path)) return;
  const Model m = read_model(path);
  for (const ModelNetwork& n : m.networks) {
    std::vector<double> pts;
    for (double t : {0.0, 0.5, 3.0})
      for (int k = 0; k < n.term.dim(); ++k) pts.push_back(n.lower[k] + t * (n.upper[k] - n.lower[k]));
    cpu::eval_network_physical(n, pts.data(), 3, 3);
  }
}

void use_baked(const std::string& path) {
  if (!is_baked_file(path)) return;
  const BakedModel m = read_baked(path);
  for (const BakedTable& t : m.tables) {
    const BakedTerm bt = make_baked_term(t, path);
    double j[kMaxJetChannels];
    for (double u : {0.0, 0.37, 2.5}) {
      double s[2] = {t.lower[0] + u * (t.upper[0] - t.lower[0]), t.lower.back() + u * (t.upper.back() - t.lower.back())};
      eval_baked_jet(bt, s, 3, j);
    }
  }
  const BakedMaterial mat = make_baked_material(m, path);
  Strain6 s;
  s << 0.1, 0.05, 0.2, 10, 5, -10;
  eval_material(mat, s);
}

// The inputs, as regression cases.
std::vector<std::string> pattern_corpus(const std::string& text) {
  auto field = [&](const std::string& block, int row, int f, const std::string& v) {
    auto lines = lines_of(text);
    std::string cur;
    int k = -1;
    for (auto& l : lines) {
      if (!l.empty() && l[0] == '*') {
        std::istringstream hs(l.substr(1));
        hs >> cur;
        k = -1;
      } else if (cur == block && !l.empty() && ++k == row) {
        std::istringstream ls(l);
        std::vector<std::string> fs;
        for (std::string x; ls >> x;) fs.push_back(x);
        fs[f] = v;
        l.clear();
        for (auto& x : fs) l += (l.empty() ? "" : " ") + x;
      }
    }
    return join(lines);
  };
  return {field("Q", 3, 3, "1e15"), field("pattern", 0, 2, "1"), field("pattern", 0, 2, "1e-30"),
          field("E", 2, 0, "1e300"), field("pattern", 0, 3, "1e300")};
}

}  // namespace

TEST(Fuzz, EveryInputKindIsReadOrRefusedNamingTheFile) {
  const auto t0 = std::chrono::steady_clock::now();
  yarnhom::test::TempDir d("fuzz");
  const fs::path keep = fs::temp_directory_path() / "yarnhom_fuzz_failures";
  fs::create_directories(keep);
  const auto files = yarnhom::test::write_small_files(d);
  Rng rng(20241122);
  const int kPatterns = 400, kH5 = 200;

  Kind pyp{"pattern", use_pattern, {}};
  {
    const std::string text = slurp(files.pattern);
    auto corpus = pattern_corpus(text);
    for (int i = 0; i < kPatterns; ++i) {
      const std::string p = d / ("p" + std::to_string(i) + ".pyp");
      std::ofstream(p, std::ios::binary) << (i < int(corpus.size()) ? corpus[i] : mutate_text(text, rng));
      pyp.mutants.push_back(p);
    }
  }
  // HDF5 kinds: the corpus cases first, then random mutants of a fresh copy each.
  auto make_h5 = [&](const std::string& name, const std::string& source,
                     const std::vector<std::function<void(const h5e::File&)>>& corpus) {
    Kind k{name, name == "dataset" ? use_dataset : name == "model" ? use_model : use_baked, {}};
    for (int i = 0; i < kH5; ++i) {
      const std::string p = d / (name + std::to_string(i) + ".h5");
      fs::copy_file(source, p);
      if (i < int(corpus.size())) corpus[i](h5e::File(p));
      else mutate_h5(p, rng);
      k.mutants.push_back(p);
    }
    return k;
  };
  Kind ds = make_h5("dataset", files.dataset,
                    {[](const h5e::File& f) { h5e::put_dataset(f, "/terms/02/energy", {hsize_t(1) << 28}); },
                     [](const h5e::File& f) { h5e::set_attr(f, "/rest", "psi0", {NAN}); },
                     [](const h5e::File& f) { h5e::set_attr_vlen_utf8(f, "/", "format", "yarnhom-dataset"); }});
  Kind model = make_h5("model", files.model,
                       {[](const h5e::File& f) { h5e::put_dataset(f, "/networks/02/history/L_S", {hsize_t(1) << 40}); },
                        [](const h5e::File& f) { h5e::set_attr(f, "/networks/0", "out_std", {0.0}); },
                        [](const h5e::File& f) { h5e::rename(f, "/networks/02", "/networks/zz"); },
                        [](const h5e::File& f) { h5e::set_attr_vlen_utf8(f, "/", "dataset", "dataset.h5"); }});
  Kind baked = make_h5("baked", files.baked,
                       {[](const h5e::File& f) { h5e::set_attr(f, "/tables/02", "knots", {2e9, 2e9}, H5T_STD_I64LE); },
                        [](const h5e::File& f) { h5e::set_attr(f, "/tables/0", "knots", {-5.0}, H5T_STD_I64LE); },
                        [](const h5e::File& f) { h5e::put_dataset(f, "/tables/02/f", {hsize_t(1) << 30, 4}); }});
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  std::vector<std::string> failures;
  int refused[4] = {0, 0, 0, 0}, ki = 0;
  for (const Kind* k : {&pyp, &ds, &model, &baked}) {
    for (const std::string& f : run_kind(*k, keep, &refused[ki])) failures.push_back(f);
    // Mutations must mostly break something: a fuzzer whose mutants all pass tests nothing.
    EXPECT_GT(refused[ki], int(k->mutants.size()) / 3) << k->name;
    ++ki;
  }
  for (const std::string& f : failures) ADD_FAILURE() << f;
  const double read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() - build_s;

  // A sample through the program: no signal, no hang, a non-zero exit names the file, < 5 s.
  struct Cli {
    const Kind* kind;
    std::string args;  // with FILE for the mutant
  };
  int through = 0;
  for (const Cli& c : {Cli{&pyp, "rve FILE --max-iterations 20 --time-limit 3"},
                       Cli{&ds, "train-all FILE -o OUT --epochs 1 -q --terms 0"},
                       Cli{&model, "bake FILE -o OUT --res1d 20 --res2d 8 --no-check"},
                       Cli{&baked, "eval FILE --term 02 --at 0.1,0.1"}}) {
    for (int i = 0; i < 6; ++i) {
      const std::string file = c.kind->mutants[i * 7 % c.kind->mutants.size()];
      std::string args = c.args;
      args.replace(args.find("FILE"), 4, file);
      if (auto o = args.find("OUT"); o != std::string::npos) args.replace(o, 3, d / "out.h5");
      const auto s0 = std::chrono::steady_clock::now();
      const auto r = yarnhom::test::run_cli_limited(args, 20);
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
      ++through;
      EXPECT_LT(r.status, 128) << args << ": ended by a signal or hung\n" << r.out;
      if (r.status != 0) {
        EXPECT_NE(r.out.find(file), std::string::npos) << args << "\n" << r.out;
      }
      EXPECT_EQ(r.out.find("std::"), std::string::npos) << args << "\n" << r.out;
      EXPECT_LT(secs, 5.0) << args;
    }
  }
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("fuzz: %zu pattern, %zu dataset, %zu model, %zu baked mutants (refused %d, %d, %d, %d; build %.1f s, "
              "read %.1f s), %d through the program, %.1f s in all\n",
              pyp.mutants.size(), ds.mutants.size(), model.mutants.size(), baked.mutants.size(), refused[0], refused[1],
              refused[2], refused[3], build_s, read_s, through, total);
  if (failures.empty()) fs::remove_all(keep);
}
