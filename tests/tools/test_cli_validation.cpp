// Issue 11, items 6-10: every bad input and option refused early and clearly. Each case goes
// through the program and asserts a non-zero exit, a message naming the file or the option and
// the rule, and a refusal in well under 5 s (the campaign's limit).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/model.hpp"
#include "tests/common/h5_edit.hpp"
#include "tests/common/pattern_text.hpp"
#include "tests/common/run_cli.hpp"
#include "tests/common/small_files.hpp"

namespace fs = std::filesystem;
using yarnhom::test::run_cli;
using yarnhom::test::TempDir;
namespace h5e = yarnhom::test::h5edit;

namespace {

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

// Runs and checks a refusal: exit status non-zero (never a signal), every `needles` string in
// the output, no "std::" (a library message that names nothing), under 5 s.
void expect_refused(const std::string& args, const std::vector<std::string>& needles) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = yarnhom::test::run_cli_limited(args);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_NE(r.status, 0) << args << "\n" << r.out;
  EXPECT_LT(r.status, 128) << args << " ended by a signal or hung\n" << r.out;
  for (const std::string& n : needles) EXPECT_NE(r.out.find(n), std::string::npos) << args << "\nwant: " << n << "\n" << r.out;
  EXPECT_EQ(r.out.find("std::"), std::string::npos) << args << "\n" << r.out;
  EXPECT_LT(secs, 5.0) << args;
}

std::string field_replaced(const std::string& text, const std::string& block, int row, int field, const std::string& v) {
  return yarnhom::test::edit_pattern_row(text, block, row, false,
                                         [&](const std::string& line) { return yarnhom::test::with_field(line, field, v); });
}

}  // namespace

// Item 6: pathological patterns are refused at once with the rule (they used to run minutes of
// rest relaxation, or give Psi ~ 1e-76), and --max-iterations and --time-limit bound the rest
// relaxation.
TEST(Validation, PathologicalPatternsAreRefusedWithTheRule) {
  TempDir d("val");
  yarnhom::test::write_small_pattern(d / "p.pyp");
  const std::string text = slurp(d / "p.pyp");
  struct Case {
    std::string block;
    int row, field;
    std::string value, needle;
  };
  for (const Case& c : {Case{"Q", 3, 3, "1e15", "twist angle"}, Case{"pattern", 0, 2, "1", "radius"},
                        Case{"pattern", 0, 2, "1e-30", "radius"}, Case{"pattern", 0, 0, "1e9", "periods"},
                        Case{"Q", 2, 2, "5", "vertex outside"}, Case{"RK", 1, 0, "1e6", "rest curvature"},
                        Case{"RL", 1, 0, "1e-12", "rest length"}, Case{"RT", 0, 0, "1e4", "rest twist"},
                        Case{"E", 2, 0, "1e300", "missing vertex 1e+300"}}) {
    const std::string p = d / ("m_" + c.block + std::to_string(c.row) + ".pyp");
    std::ofstream(p) << field_replaced(text, c.block, c.row, c.field, c.value);
    expect_refused("rve " + p, {p, c.needle});
    expect_refused("produce " + p + " -o " + d / "ds.h5 --terms 0 --preset tiny", {p, c.needle});
  }
  // The iteration limit bounds the rest relaxation too (it used to take at least 200).
  expect_refused("rve " + d / "p.pyp" + " --max-iterations 1", {"at rest", "max_iterations after 1 iterations"});
  expect_refused("rve " + d / "p.pyp" + " --time-limit 1e-9", {"at rest", "time_limit"});
}

// Item 7: sizes declared by a file are checked before anything is read, naming the file and
// the dataset (a 2^40-entry history used to give "std::bad_alloc", 2^28 energies were read in
// full before "wrong shape").
TEST(Validation, HugeDeclaredSizesAreRefusedBeforeReading) {
  TempDir d("val");
  const auto f = yarnhom::test::write_small_files(d);
  fs::copy_file(f.model, d / "m_hist.h5");
  h5e::put_dataset(h5e::File(d / "m_hist.h5"), "/networks/02/history/val_loss", {hsize_t(1) << 40});
  expect_refused("eval " + d / "m_hist.h5" + " --term 0 --at 0.1", {d / "m_hist.h5", "/networks/02/history/val_loss", "wrong shape"});

  fs::copy_file(f.dataset, d / "d_big.h5");
  h5e::put_dataset(h5e::File(d / "d_big.h5"), "/terms/02/energy", {hsize_t(1) << 28});
  expect_refused("train-all " + d / "d_big.h5" + " -o " + d / "m.h5 --epochs 1", {d / "d_big.h5", "/terms/02/energy", "wrong shape"});
  fs::copy_file(f.dataset, d / "d_huge.h5");
  h5e::put_dataset(h5e::File(d / "d_huge.h5"), "/terms/0/strain", {hsize_t(1) << 33, 1});
  expect_refused("train-all " + d / "d_huge.h5" + " -o " + d / "m.h5 --epochs 1", {d / "d_huge.h5", "/terms/0/strain"});

  fs::copy_file(f.baked, d / "b_knots.h5");
  h5e::set_attr(h5e::File(d / "b_knots.h5"), "/tables/02", "knots", {2e9, 2e9}, H5T_STD_I64LE);
  expect_refused("eval " + d / "b_knots.h5" + " --term 02 --at 0.1,0.1", {d / "b_knots.h5", "/tables/02", "knots"});
  fs::copy_file(f.baked, d / "b_shape.h5");
  h5e::put_dataset(h5e::File(d / "b_shape.h5"), "/tables/0/f_x", {hsize_t(1) << 36});
  expect_refused("eval " + d / "b_shape.h5" + " --term 0 --at 0.1", {d / "b_shape.h5", "/tables/0/f_x", "wrong shape"});
}

// Item 8: strains and points are finite (eval used to print NaN/inf with exit status 0).
TEST(Validation, NonFiniteStrainsAndPointsAreRefused) {
  TempDir d("val");
  const auto f = yarnhom::test::write_small_files(d);
  for (const std::string& file : {f.model, f.baked}) {
    expect_refused("eval " + file + " --term 02 --at nan,0.2", {"--at", "not a finite number"});
    expect_refused("eval " + file + " --term 0 --at inf", {"--at", "not a finite number"});
    expect_refused("eval " + file + " --term 02 --at 1e308,0.2", {"1e+308", "s_x must lie within +-1e6"});
  }
  std::ofstream(d / "pts.csv") << "s_x\n0.1\nnan\n";
  expect_refused("eval " + f.model + " --term 0 --points " + d / "pts.csv", {d / "pts.csv" + ":3", "not a finite number"});
  expect_refused("rve stockinette --strain 0,nan,0,0,0,0", {"--strain", "not a finite number"});
}

// Item 9: invalid options are refused when parsed, naming the option (they used to be accepted:
// --threads -1, --lr 0, --terms '' training everything, --epochs -1 running 500, ...).
TEST(Validation, InvalidOptionsAreRefusedNamingThem) {
  TempDir d("val");
  const auto f = yarnhom::test::write_small_files(d);
  const std::string train = "train-all " + f.dataset + " -o " + d / "m.h5 --epochs 1 -q ";
  for (const std::string o : {"--threads -1", "--lr -1", "--lr 0", "--lr nan", "--w-s -100", "--w-c inf",
                               "--terms ''", "--hidden 0,4", "--stencil-eps 0", "--off-domain -1",
                               "--polish-memory-2d 0", "--polish-memory-2d 33"})
    expect_refused(train + o, {o.substr(0, o.find(' '))});
  const std::string produce = "produce stockinette -o " + d / "ds.h5 --terms 0 ";
  for (const std::string o : {"--threads -3", "--sectors 0", "--sectors -1", "--terms ''", "--preset huge", "--tile 0,1",
                               "--tile 2", "--tile 1.5,1", "--tile 65,1"})
    expect_refused(produce + o, {o.substr(0, o.find(' '))});
  std::ofstream(d / "ranges.txt") << "0 -0.1 0.5\nx y z\n";
  expect_refused(produce + "--ranges " + d / "ranges.txt", {d / "ranges.txt", "line 2"});
  std::ofstream(d / "ranges4.txt") << "4 -1 1\n";
  expect_refused(produce + "--ranges " + d / "ranges4.txt", {d / "ranges4.txt", "line 1"});
  for (const std::string o : {"--epochs -1", "--threads -1"})
    expect_refused("pipeline synthetic -o " + d / "run " + o, {o.substr(0, o.find(' '))});
  // produce's tiny preset is not synth's: refused before any work.
  expect_refused("pipeline synthetic -o " + d / "run --preset tiny", {"--preset tiny", "quick or paper"});
  EXPECT_FALSE(fs::exists(d / "run"));
  for (const std::string o : {"--reference-res1d 1", "--reference-res2d 1", "--reference-res2d 20000"})
    expect_refused("study bake-resolution stockinette -o " + d / "t4 " + o, {o.substr(0, o.find(' '))});
  EXPECT_FALSE(fs::exists(d / "t4"));
  for (const std::string o : {"--tolerance -1", "--tolerance 0", "--tolerance nan", "--max-iterations 0"})
    expect_refused("rve stockinette " + o, {o.substr(0, o.find(' '))});
  expect_refused("error " + f.model + " --samples 0", {"--samples"});
  expect_refused("eval " + f.model + " --term 04 --at 0.1", {"--term", "unknown term"});
}

// Item 10: inconsistent files are refused, naming the file (they used to be accepted or to
// hang); a variable-length UTF-8 string attribute, as h5py writes one, is read.
TEST(Validation, InconsistentFilesAreRefusedAndH5pyStringsAccepted) {
  TempDir d("val");
  const auto f = yarnhom::test::write_small_files(d);
  fs::copy_file(f.model, d / "m_std.h5");
  h5e::set_attr(h5e::File(d / "m_std.h5"), "/networks/0", "out_std", {0.0});
  expect_refused("eval " + d / "m_std.h5" + " --term 0 --at 0.1", {d / "m_std.h5", "/networks/0", "out_std"});

  fs::copy_file(f.model, d / "m_name.h5");
  h5e::rename(h5e::File(d / "m_name.h5"), "/networks/02", "/networks/zz");
  expect_refused("bake " + d / "m_name.h5" + " -o " + d / "b.h5", {d / "m_name.h5", "/networks/zz", "unknown term"});

  fs::copy_file(f.dataset, d / "d_nan.h5");
  h5e::set_attr(h5e::File(d / "d_nan.h5"), "/rest", "psi0", {std::nan("")});
  expect_refused("train-all " + d / "d_nan.h5" + " -o " + d / "m.h5 --epochs 1", {d / "d_nan.h5", "psi0"});
  fs::copy_file(f.dataset, d / "d_q.h5");
  {
    const std::vector<double> q = {0.0, std::nan(""), 1.0};
    h5e::put_dataset(h5e::File(d / "d_q.h5"), "/rest/q", {3}, &q);
  }
  expect_refused("train-all " + d / "d_q.h5" + " -o " + d / "m.h5 --epochs 1", {d / "d_q.h5", "/rest/q", "non-finite"});

  // A FIFO named by the model's dataset attribute must not hang bake (the test's own limit:
  // `timeout` ends a hang with status 124, which expect_refused's message check then fails).
  const std::string fifo = d / "fifo.h5";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  fs::copy_file(f.model, d / "m_fifo.h5");
  h5e::set_attr_fixed(h5e::File(d / "m_fifo.h5"), "/", "dataset", fifo);
  expect_refused("bake " + d / "m_fifo.h5" + " -o " + d / "b.h5", {fifo, "not a regular file"});
  expect_refused("train-all " + fifo + " -o " + d / "m.h5", {fifo, "FIFO"});

  // h5py's strings: variable-length UTF-8. Every string attribute of a model rewritten so is
  // read, and gives the same numbers.
  fs::copy_file(f.model, d / "m_vlen.h5");
  {
    h5e::File file(d / "m_vlen.h5");
    h5e::set_attr_vlen_utf8(file, "/", "format", "yarnhom-model");
    h5e::set_attr_vlen_utf8(file, "/", "dataset", f.dataset);
    h5e::set_attr_vlen_utf8(file, "/networks/0", "activation", "sigmoid");
    h5e::set_attr_vlen_utf8(file, "/networks/0", "status", "ok");
  }
  const auto a = run_cli("eval " + f.model + " --term 0 --at 0.1");
  const auto b = run_cli("eval " + d / "m_vlen.h5" + " --term 0 --at 0.1");
  ASSERT_EQ(b.status, 0) << b.out;
  EXPECT_EQ(a.out, b.out);
  // An array of strings where one is expected is refused, not read past its end.
  fs::copy_file(f.model, d / "m_arr.h5");
  h5e::set_attr_fixed(h5e::File(d / "m_arr.h5"), "/", "dataset", "abc", 4);
  expect_refused("bake " + d / "m_arr.h5" + " -o " + d / "b.h5", {d / "m_arr.h5", "not a single string"});
}
