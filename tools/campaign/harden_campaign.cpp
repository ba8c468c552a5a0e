// harden_campaign: issue 11's acceptance campaign, run against any yarnhom binary (so that the
// same figures can be taken before and after a change). Not a test: it takes minutes.
//
//   harden_campaign --yarnhom build/tools/yarnhom --pattern ../shared/patterns/stockinette.pyp
//                   [--kills 30] [--pipeline-kills 14] [--seed 1] [--work /tmp/campaign]
//
// A. Killed produce: `produce PATTERN --preset quick --terms 0,02` killed (SIGKILL) at a random
//    moment of an uninterrupted run's duration, then rerun to completion; the resumed dataset
//    is compared with the uninterrupted one, every array bit for bit (and the samples read back,
//    and the kills that cut a checkpoint record, are counted from the rerun's summary). Also counts the
//    temporaries a kill left and whether the rerun removed them.
// B. Clobbering: outputs that are special files (FIFO, socket, character device when we may make
//    one), folders, links, or one of the command's inputs; counts what was replaced or changed.
// C. Refusals: bad options and bad files; each must exit non-zero, within 5 s, with a message
//    that names the file or the option, never "std::..." and never a signal; NaN or inf printed
//    with exit status 0 counts as unclean too.
// D. Killed pipeline: SIGKILL at a random moment; counts stage processes still running 2 s later.
#include <fcntl.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/dataset.hpp"
#include "tests/common/pattern_text.hpp"
#include "tests/common/process_tree.hpp"
#include "tools/campaign/campaign_util.hpp"
#include "tools/campaign/campaign_parts.hpp"


namespace {

using namespace campaign;

// Every array and scalar of two datasets, bit for bit.
bool same_bits(const yarnhom::Dataset& a, const yarnhom::Dataset& b, std::string* why) {
  auto eq = [](const std::vector<double>& x, const std::vector<double>& y) {
    return x.size() == y.size() && (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0);
  };
  if (std::memcmp(&a.psi0, &b.psi0, sizeof(double)) != 0) return *why = "psi0", false;
  if (!eq(a.rest_q, b.rest_q)) return *why = "rest/q", false;
  if (a.terms.size() != b.terms.size()) return *why = "number of terms", false;
  for (size_t t = 0; t < a.terms.size(); ++t) {
    const auto &x = a.terms[t], &y = b.terms[t];
    if (x.n != y.n) return *why = "term " + x.term.name + " sample count", false;
    if (!eq(x.strain, y.strain) || !eq(x.energy, y.energy) || !eq(x.gradient, y.gradient) || !eq(x.raw, y.raw)) {
      double worst = 0;
      for (size_t i = 0; i < x.raw.size() && i < y.raw.size(); ++i) worst = std::max(worst, std::abs(x.raw[i] - y.raw[i]));
      char buf[128];
      std::snprintf(buf, sizeof buf, "term %s differs (max |raw difference| %.3g J/m^2)", x.term.name.c_str(), worst);
      return *why = buf, false;
    }
  }
  return true;
}

// ---------------- A. killed produce ----------------
void campaign_resume(const std::string& pattern, int kills, std::mt19937_64& rng, const fs::path& work) {
  const fs::path dir = work / "resume";
  fs::create_directories(dir);
  const std::string ref = (dir / "ref.h5").string();
  fs::remove(ref);
  fs::remove(ref + ".partial");
  auto produce = [&](const std::string& out) {
    return cmd({"produce", pattern, "--preset", "quick", "--terms", "0,02", "--threads", "2", "-o", out});
  };
  Run r = run(produce(ref), 3600);
  if (r.status != 0) {
    std::printf("A. reference produce failed (status %d):\n%s\n", r.status, r.out.c_str());
    return;
  }
  const double T = r.seconds;
  const yarnhom::Dataset reference = yarnhom::read_dataset(ref);
  std::printf("A. killed produce: reference run %.1f s; %d kills at uniform random moments of it\n", T, kills);
  int wrong = 0, failed = 0, finished_before_kill = 0, temporaries_left = 0, temporaries_after_rerun = 0, resumed_runs = 0;
  int resumed_samples = 0, cut_records = 0;
  std::uniform_real_distribution<double> when(0.02, 1.0);
  for (int k = 0; k < kills; ++k) {
    const std::string out = (dir / ("run" + std::to_string(k) + ".h5")).string();
    fs::remove(out);
    fs::remove(out + ".partial");
    const double at = when(rng) * T;
    const pid_t pid = spawn(produce(out), (dir / "kill.log").string());
    const auto t0 = Clock::now();
    int st = 0;
    bool exited = false;
    while (since(t0) < at)
      if (::waitpid(pid, &st, WNOHANG) == pid) {
        exited = true;
        break;
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    if (!exited) {
      ::kill(-pid, SIGKILL);
      ::waitpid(pid, &st, 0);
    } else {
      ++finished_before_kill;
    }
    temporaries_left += count_partials(dir);
    const bool had_checkpoint = fs::exists(out + ".partial");
    r = run(produce(out), 3600);
    temporaries_after_rerun += count_partials(dir);
    if (r.status != 0) {
      ++failed;
      std::printf("   kill %2d at %5.1f s: rerun failed (status %d): %s\n", k, at, r.status, r.out.substr(0, 300).c_str());
      continue;
    }
    resumed_runs += had_checkpoint;
    // What the rerun read back: "resumed     N samples ... (its last record, cut by the kill ...)".
    int samples = 0;
    const size_t at_resumed = r.out.find("\nresumed ");
    if (at_resumed != std::string::npos) samples = std::atoi(r.out.c_str() + at_resumed + 9);
    const bool cut = r.out.find("cut by the kill") != std::string::npos;
    resumed_samples += samples;
    cut_records += cut;
    std::string why;
    const bool same = same_bits(reference, yarnhom::read_dataset(out), &why);
    wrong += !same;
    std::string how;
    if (had_checkpoint) how = " (checkpoint: " + std::to_string(samples) + " samples resumed" + (cut ? ", a record cut" : "") + ")";
    std::printf("   kill %2d at %5.1f s%s: %s\n", k, at, how.c_str(), same ? "identical" : ("DIFFERENT: " + why).c_str());
    fs::remove(out);
  }
  std::printf("A. result: %d wrong resumed datasets of %d kills (%d resumed from a checkpoint: %d samples in all, %d "
              "with a record cut by the kill; %d finished before the kill, %d reruns failed); temporaries left by "
              "kills %d, after the reruns %d\n\n",
              wrong, kills, resumed_runs, resumed_samples, cut_records, finished_before_kill, failed, temporaries_left,
              temporaries_after_rerun);
}

// ---------------- B. clobbering ----------------
void campaign_clobber(const fs::path& work, const std::string& pattern) {
  const fs::path dir = fresh_model_dir(work / "clobber");
  auto p = [&](const std::string& f) { return (dir / f).string(); };
  fs::copy_file(pattern, p("pattern.pyp"));
  int cases = 0, clobbered = 0;
  auto check = [&](const std::string& what, bool ok) {
    ++cases;
    if (!ok) ++clobbered;
    std::printf("   %-60s %s\n", what.c_str(), ok ? "kept" : "CLOBBERED");
  };
  std::printf("B. clobbering\n");
  // Special files and folders as -o.
  ::mkfifo(p("fifo").c_str(), 0644);
  run(cmd({"synth", "-o", p("fifo")}), 20);
  check("synth -o FIFO", file_type(p("fifo")) == S_IFIFO);
  {
    const int s = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::snprintf(a.sun_path, sizeof a.sun_path, "%s", p("sock").c_str());
    if (::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
      run(cmd({"synth", "-o", p("sock")}), 20);
      check("synth -o socket", file_type(p("sock")) == S_IFSOCK);
    }
    ::close(s);
  }
  if (::mknod(p("dev").c_str(), S_IFCHR | 0600, makedev(1, 3)) == 0) {
    run(cmd({"synth", "-o", p("dev")}), 20);
    check("synth -o character device (made for the purpose)", file_type(p("dev")) == S_IFCHR);
    run(cmd({"train-all", p("d.h5"), "-o", p("dev"), "--epochs", "1", "-q"}), 20);
    check("train-all -o character device", file_type(p("dev")) == S_IFCHR);
  }
  fs::create_directories(p("folder"));
  run(cmd({"synth", "-o", p("folder")}), 20);
  check("synth -o folder", fs::is_directory(p("folder")) && fs::is_empty(p("folder")));
  // A link to a regular file: the target is written, the link stays (documented: followed).
  std::ofstream(p("target.h5")) << "x";
  fs::create_symlink(p("target.h5"), p("link.h5"));
  run(cmd({"synth", "-o", p("link.h5")}), 20);
  check("synth -o symbolic link (stays a link)", fs::is_symlink(p("link.h5")));
  // Inputs as outputs, by name, hard link and symbolic link.
  fs::create_hard_link(p("d.h5"), p("hard.h5"));
  fs::create_symlink(p("m.h5"), p("soft.h5"));
  const std::string d0 = slurp(p("d.h5")), m0 = slurp(p("m.h5")), p0 = slurp(p("pattern.pyp"));
  struct Case {
    std::vector<std::string> args;
    std::string what, file, before;
  };
  const std::vector<Case> same = {
      {cmd({"train-all", p("d.h5"), "-o", p("d.h5"), "--epochs", "2", "-q"}), "train-all D -o D", p("d.h5"), d0},
      {cmd({"train-all", p("d.h5"), "-o", p("hard.h5"), "--epochs", "2", "-q"}), "train-all D -o hard link of D", p("d.h5"), d0},
      {cmd({"bake", p("m.h5"), "-o", p("m.h5")}), "bake M -o M", p("m.h5"), m0},
      {cmd({"bake", p("m.h5"), "-o", p("soft.h5")}), "bake M -o symbolic link to M", p("m.h5"), m0},
      {cmd({"bake", p("m.h5"), "-o", p("d.h5")}), "bake M -o (the dataset M names)", p("d.h5"), d0},
      {cmd({"error", p("m.h5"), "--csv", p("d.h5")}), "error M --csv D", p("d.h5"), d0},
      {cmd({"produce", p("pattern.pyp"), "-o", p("pattern.pyp"), "--terms", "0", "--preset", "quick"}), "produce P -o P", p("pattern.pyp"), p0},
      {cmd({"rve", p("pattern.pyp"), "--pattern-out", p("pattern.pyp")}), "rve P --pattern-out P", p("pattern.pyp"), p0},
  };
  for (const Case& c : same) {
    run(c.args, 120);
    check(c.what, slurp(c.file) == c.before);
  }
  std::printf("B. result: %d clobbered special files or inputs of %d cases\n\n", clobbered, cases);
}

// ---------------- C. refusals ----------------
namespace h5 {
void set_double(const std::string& file, const std::string& obj, const std::string& name, double v) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  hid_t o = H5Oopen(f, obj.c_str(), H5P_DEFAULT);
  if (H5Aexists(o, name.c_str()) > 0) H5Adelete(o, name.c_str());
  hid_t sp = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(o, name.c_str(), H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_DOUBLE, &v);
  H5Aclose(a);
  H5Sclose(sp);
  H5Oclose(o);
  H5Fclose(f);
}
void set_string(const std::string& file, const std::string& obj, const std::string& name, const std::string& v,
                bool vlen) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  hid_t o = H5Oopen(f, obj.c_str(), H5P_DEFAULT);
  if (H5Aexists(o, name.c_str()) > 0) H5Adelete(o, name.c_str());
  hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, vlen ? H5T_VARIABLE : v.size());
  if (vlen) H5Tset_cset(t, H5T_CSET_UTF8);
  hid_t sp = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(o, name.c_str(), t, sp, H5P_DEFAULT, H5P_DEFAULT);
  const char* s = v.c_str();
  H5Awrite(a, t, vlen ? static_cast<const void*>(&s) : static_cast<const void*>(s));
  H5Aclose(a);
  H5Sclose(sp);
  H5Tclose(t);
  H5Oclose(o);
  H5Fclose(f);
}
void huge(const std::string& file, const std::string& path, std::vector<hsize_t> dims) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  H5Ldelete(f, path.c_str(), H5P_DEFAULT);
  hid_t sp = H5Screate_simple(int(dims.size()), dims.data(), nullptr);
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  std::vector<hsize_t> chunk(dims.size(), 1);
  H5Pset_chunk(dcpl, int(dims.size()), chunk.data());
  hid_t d = H5Dcreate2(f, path.c_str(), H5T_IEEE_F64LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  H5Dclose(d);
  H5Pclose(dcpl);
  H5Sclose(sp);
  H5Fclose(f);
}
void rename(const std::string& file, const std::string& from, const std::string& to) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  H5Lmove(f, from.c_str(), f, to.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  H5Fclose(f);
}
}  // namespace h5

std::string replace_field(const std::string& text, const std::string& block, int row, int field, const std::string& v) {
  return yarnhom::test::edit_pattern_row(text, block, row, true,
                                         [&](const std::string& line) { return yarnhom::test::with_field(line, field, v); });
}

void campaign_refusals(const fs::path& work, const std::string& pattern) {
  const fs::path dir = fresh_model_dir(work / "refuse");
  auto p = [&](const std::string& f) { return (dir / f).string(); };
  run(cmd({"bake", p("m.h5"), "-o", p("b.h5"), "--res1d", "20", "--res2d", "8"}));
  const std::string text = slurp(pattern);
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> names;  // one of these must appear in the message
  };
  std::vector<Case> cases;
  auto mut = [&](const std::string& name, const std::string& block, int row, int field, const std::string& v) {
    std::ofstream(p(name)) << replace_field(text, block, row, field, v);
    cases.push_back({cmd({"rve", p(name)}), {p(name)}});
    cases.push_back({cmd({"produce", p(name), "-o", p("x.h5"), "--terms", "0"}), {p(name)}});
  };
  mut("twist.pyp", "Q", 3, 3, "1e15");
  mut("radius1.pyp", "pattern", 0, 2, "1");
  mut("radius_tiny.pyp", "pattern", 0, 2, "1e-30");
  mut("edge.pyp", "E", 2, 0, "1e300");
  mut("period.pyp", "pattern", 0, 0, "1e9");
  mut("n.pyp", "pattern", 0, 3, "1e300");
  auto copy = [&](const std::string& from, const std::string& to) {
    fs::copy_file(p(from), p(to), fs::copy_options::overwrite_existing);
    return p(to);
  };
  std::string f;
  f = copy("m.h5", "m_hist.h5"), h5::huge(f, "/networks/02/history/val_loss", {hsize_t(1) << 40});
  cases.push_back({cmd({"eval", f, "--term", "0", "--at", "0.1"}), {f}});
  f = copy("d.h5", "d_big.h5"), h5::huge(f, "/terms/02/energy", {hsize_t(1) << 28});
  cases.push_back({cmd({"train-all", f, "-o", p("out.h5"), "--epochs", "1"}), {f}});
  f = copy("b.h5", "b_knots.h5"), h5::huge(f, "/tables/02/f", {hsize_t(1) << 20, hsize_t(1) << 20});
  cases.push_back({cmd({"eval", f, "--term", "02", "--at", "0.1,0.1"}), {f}});
  f = copy("m.h5", "m_std.h5"), h5::set_double(f, "/networks/0", "out_std", 0);
  cases.push_back({cmd({"eval", f, "--term", "0", "--at", "0.1"}), {f}});
  f = copy("m.h5", "m_name.h5"), h5::rename(f, "/networks/02", "/networks/zz");
  cases.push_back({cmd({"bake", f, "-o", p("out.h5")}), {f}});
  f = copy("d.h5", "d_nan.h5"), h5::set_double(f, "/rest", "psi0", NAN);
  cases.push_back({cmd({"train-all", f, "-o", p("out.h5"), "--epochs", "1"}), {f}});
  ::mkfifo(p("fifo.h5").c_str(), 0644);
  f = copy("m.h5", "m_fifo.h5"), h5::set_string(f, "/", "dataset", p("fifo.h5"), false);
  cases.push_back({cmd({"bake", f, "-o", p("out.h5")}), {p("fifo.h5"), f}});
  std::ofstream(p("pts.csv")) << "0.1\nnan\n";
  for (const std::string& file : {p("m.h5"), p("b.h5")}) {
    cases.push_back({cmd({"eval", file, "--term", "02", "--at", "nan,0.2"}), {"--at"}});
    cases.push_back({cmd({"eval", file, "--term", "02", "--at", "1e308,0.2"}), {"--at", "1e+308"}});
    cases.push_back({cmd({"eval", file, "--term", "0", "--at", "inf"}), {"--at"}});
    cases.push_back({cmd({"eval", file, "--term", "0", "--points", p("pts.csv")}), {p("pts.csv")}});
  }
  const std::string D = p("d.h5"), O = p("o.h5");
  for (auto o : std::vector<std::vector<std::string>>{{"--threads", "-1"}, {"--lr", "-1"}, {"--lr", "0"}, {"--lr", "nan"},
                                                       {"--w-s", "-100"}, {"--terms", ""}, {"--epochs", "-1"},
                                                       {"--hidden", "0"}, {"--batch-2d", "0"}})
    cases.push_back({cmd({"train-all", D, "-o", O, "--epochs", "1", o[0], o[1]}), {o[0]}});
  for (auto o : std::vector<std::vector<std::string>>{{"--threads", "-3"}, {"--sectors", "0"}, {"--sectors", "-1"},
                                                       {"--terms", ""}, {"--preset", "nope"}})
    cases.push_back({cmd({"produce", pattern, "-o", O, o[0], o[1]}), {o[0]}});
  std::ofstream(p("ranges.txt")) << "x y z\n";
  cases.push_back({cmd({"produce", pattern, "-o", O, "--ranges", p("ranges.txt")}), {p("ranges.txt")}});
  for (auto o : std::vector<std::vector<std::string>>{{"--epochs", "-1"}, {"--threads", "-1"}})
    cases.push_back({cmd({"pipeline", "synthetic", "-o", p("run"), o[0], o[1]}), {o[0]}});
  for (auto v : {"-1", "0", "nan"}) cases.push_back({cmd({"rve", pattern, "--tolerance", v}), {"--tolerance"}});
  cases.push_back({cmd({"rve", pattern, "--strain", "nan,0,0,0,0,0"}), {"--strain"}});
  cases.push_back({cmd({"train-all", p("missing.h5"), "-o", O}), {p("missing.h5")}});
  cases.push_back({cmd({"train-all", D, "-o", p("no/such/dir/m.h5")}), {p("no/such/dir/m.h5")}});
  cases.push_back({cmd({"train-all", D, "-o", dir.string()}), {dir.string()}});

  int unclean = 0, slow = 0, accepted = 0;
  std::printf("C. refusals (%zu bad command lines and files)\n", cases.size());
  for (const Case& c : cases) {
    const Run r = run(c.args, 300);
    std::string line;
    for (size_t i = 1; i < c.args.size(); ++i) line += (i > 1 ? " " : "") + (c.args[i].empty() ? "''" : c.args[i]);
    bool named = false;
    for (const auto& n : c.names) named = named || r.out.find(n) != std::string::npos;
    const bool nonfinite = r.out.find("nan") != std::string::npos || r.out.find("inf") != std::string::npos;
    std::string verdict;
    if (r.status >= 128) verdict = "UNCLEAN: signal or hang (" + std::to_string(r.status) + ")";
    else if (r.status == 0) verdict = nonfinite ? "UNCLEAN: NaN/inf printed with status 0" : "ACCEPTED";
    else if (!named) verdict = "UNCLEAN: message names neither the file nor the option";
    else if (r.out.find("std::") != std::string::npos) verdict = "UNCLEAN: a library message";
    else verdict = "refused";
    if (verdict.rfind("UNCLEAN", 0) == 0) ++unclean;
    if (verdict == "ACCEPTED") ++accepted;
    if (r.status != 0 && r.seconds > 5) ++slow;
    std::string msg = r.out.substr(0, r.out.find('\n'));
    if (msg.size() > 150) msg = msg.substr(0, 150) + "...";
    std::printf("   %6.2f s  %-9s %s\n            %s\n", r.seconds, verdict.substr(0, verdict.find(':')).c_str(),
                line.c_str(), msg.c_str());
  }
  std::printf("C. result: %d unclean, %d accepted (should be refused), %d refusals over 5 s, of %zu cases\n\n", unclean,
              accepted, slow, cases.size());
}

// ---------------- D. killed pipeline ----------------
using yarnhom::test::alive;
using yarnhom::test::descendants;

void campaign_pipeline(const fs::path& work, int kills, std::mt19937_64& rng) {
  const fs::path dir = work / "pipeline";
  fs::create_directories(dir);
  int survivors = 0, with_stage = 0;
  std::uniform_real_distribution<double> when(0.3, 12.0);
  std::printf("D. killed pipeline (%d SIGKILLs at random moments of `pipeline synthetic --epochs 200`)\n", kills);
  for (int k = 0; k < kills; ++k) {
    const std::string run_dir = (dir / ("run" + std::to_string(k))).string();
    fs::remove_all(run_dir);
    const pid_t pid = spawn(cmd({"pipeline", "synthetic", "-o", run_dir, "--epochs", "200"}), (dir / "log").string());
    const double at = when(rng);
    const auto t0 = Clock::now();
    std::vector<pid_t> seen;
    while (since(t0) < at) {
      for (pid_t c : descendants(pid))
        if (std::find(seen.begin(), seen.end(), c) == seen.end()) seen.push_back(c);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const std::vector<pid_t> stage = descendants(pid);
    ::kill(pid, SIGKILL);  // the pipeline alone, as a user's kill -9 would
    ::waitpid(pid, nullptr, 0);
    std::this_thread::sleep_for(std::chrono::seconds(2));
    int left = 0;
    for (pid_t c : stage) left += alive(c);
    survivors += left > 0;
    with_stage += !stage.empty();
    std::printf("   kill %2d at %5.1f s: %zu stage process(es) running, %d still running 2 s later\n", k, at, stage.size(),
                left);
    for (pid_t c : stage)
      if (alive(c)) ::kill(c, SIGKILL);
  }
  std::printf("D. result: %d of %d kills left stages running (%d kills hit a running stage)\n\n", survivors, kills,
              with_stage);
}

}  // namespace

// An empty folder `dir` holding a small synthetic dataset d.h5 and a 2-epoch model m.h5 of two terms.
fs::path campaign::fresh_model_dir(const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  run(cmd({"synth", "-o", (dir / "d.h5").string()}));
  run(cmd({"train-all", (dir / "d.h5").string(), "-o", (dir / "m.h5").string(), "--epochs", "2", "--terms", "0,02", "-q"}));
  return dir;
}

// Runs one part in a child whose output goes to WORK/done/PART.log, renamed from .partial when
// the part ends: a campaign interrupted and started again with the same --work prints the parts
// it finished from their logs and runs only the others.
bool run_part(char part, const std::string& parts, const fs::path& work, const std::function<void()>& body) {
  if (parts.find(part) == std::string::npos) return true;
  const fs::path done = work / "done" / (std::string(1, part) + ".log");
  fs::create_directories(done.parent_path());
  if (!fs::exists(done)) {
    std::fflush(stdout);
    const std::string partial = done.string() + ".partial";
    const pid_t pid = ::fork();
    if (pid == 0) {
      const int fd = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      body();
      std::fflush(stdout);
      ::_exit(0);
    }
    int st = 0;
    ::waitpid(pid, &st, 0);
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
      std::printf("part %c did not finish (status %d); its log so far: %s\n", part, st, partial.c_str());
      return false;
    }
    fs::rename(partial, done);
  } else {
    std::printf("(part %c: finished by an earlier, interrupted run of the campaign)\n", part);
  }
  std::fputs(slurp(done.string()).c_str(), stdout);
  std::fflush(stdout);
  return true;
}

int main(int argc, char** argv) {
  CLI::App app{"issue 11's hardening campaign against a yarnhom binary (minutes; not a test)"};
  std::string pattern, work = (fs::temp_directory_path() / "yarnhom_campaign").string(), parts = "ABCDEFG";
  int kills = 30, pipeline_kills = 14;
  uint64_t seed = 1;
  app.add_option("--yarnhom", g_bin, "The yarnhom binary to test")->required()->check(CLI::ExistingFile);
  app.add_option("--pattern", pattern, "A .pyp pattern for produce and rve (the issue used the paper's stockinette)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--kills", kills, "Kills of produce (A)");
  app.add_option("--pipeline-kills", pipeline_kills, "Kills of pipeline (D)");
  app.add_option("--seed", seed, "Seed of the kill moments");
  app.add_option("--work", work, "Scratch folder: a campaign interrupted and started again with the same one runs only the parts it had not finished (removed at the end)");
  bool keep = false;
  app.add_flag("--keep", keep, "Keep the scratch folder at the end (to look at an input that failed)");
  app.add_option("--parts", parts, "Which parts to run, e.g. AC (default ABCDEFG)");
  campaign::NewPartsOptions nopt;
  app.add_option("--strip-pattern", nopt.strip_pattern,
                 "A pattern strip holds together at 3.5 x 2.7 mm (the tests' ../shared/patterns/stocktiny.pyp): "
                 "parts E-G's strip, accuracy and study runs")
      ->check(CLI::ExistingFile);
  app.add_option("--scene-mutants", nopt.scene_mutants, "Scene-file mutants (E2)");
  app.add_option("--hylc-mutants", nopt.hylc_mutants, "HYLC material JSON mutants (E3)");
  app.add_option("--baked-mutants", nopt.baked_mutants, "Baked files with a corrupted byte (E5)");
  app.add_option("--sim-kills", nopt.sim_kills, "Kills of sim (G)");
  app.add_option("--strip-kills", nopt.strip_kills, "Kills of strip (G)");
  app.add_option("--accuracy-kills", nopt.accuracy_kills, "Kills of accuracy (G)");
  CLI11_PARSE(app, argc, argv);
  g_bin = fs::absolute(g_bin).string();
  pattern = fs::absolute(pattern).string();
  fs::create_directories(work);
  if (nopt.strip_pattern.empty()) {
    const fs::path tiny = fs::path(pattern).parent_path() / "stocktiny.pyp";
    nopt.strip_pattern = fs::exists(tiny) ? tiny.string() : std::string();
  }
  if (nopt.strip_pattern.empty() && parts.find_first_of("EFG") != std::string::npos) {
    std::fprintf(stderr, "parts E-G need --strip-pattern (stocktiny.pyp was not found beside --pattern)\n");
    return 1;
  }
  nopt.strip_pattern = fs::absolute(nopt.strip_pattern).string();
  nopt.check_pattern = pattern;
  std::printf("campaign: %s, pattern %s, strip pattern %s, seed %llu, parts %s, work %s\n\n", g_bin.c_str(),
              pattern.c_str(), nopt.strip_pattern.c_str(), (unsigned long long)seed, parts.c_str(), work.c_str());
  const auto t0 = Clock::now();
  // Each part its own generator (part A's is the seed's, as before parts E-G existed).
  auto rng_of = [&](char part) { return std::mt19937_64(part == 'A' ? seed : seed * 1000 + uint64_t(part)); };
  const fs::path w = work;
  bool ok = true;
  // In the order --parts gives them (the new parts first, for instance: EFGBCDA).
  for (char part : parts) {
    std::function<void()> body;
    switch (part) {
      case 'A': body = [&] { auto r = rng_of('A'); campaign_resume(pattern, kills, r, w); }; break;
      case 'B': body = [&] { campaign_clobber(w, pattern); }; break;
      case 'C': body = [&] { campaign_refusals(w, pattern); }; break;
      case 'D': body = [&] { auto r = rng_of('D'); campaign_pipeline(w, pipeline_kills, r); }; break;
      case 'E': body = [&] { auto r = rng_of('E'); campaign::part_e_refusals(w, nopt, r); }; break;
      case 'F': body = [&] { campaign::part_f_outputs(w, nopt); }; break;
      case 'G': body = [&] { auto r = rng_of('G'); campaign::part_g_kills(w, nopt, r); }; break;
      default: std::fprintf(stderr, "--parts: no part %c (A-G)\n", part); return 1;
    }
    ok &= run_part(part, parts, w, body);
  }
  std::printf("campaign: %.0f s in this run\n", since(t0));
  if (!ok) return 1;
  if (!keep) fs::remove_all(work);
  return 0;
}
