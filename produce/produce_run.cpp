#include "produce/produce_run.hpp"

#include <omp.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <tuple>

#include "core/cluster.hpp"
#include "core/console.hpp"
#include "core/dataset.hpp"
#include "core/error.hpp"
#include "core/file_checks.hpp"
#include "core/number_list.hpp"
#include "core/scaled_eigen.hpp"
#include "numerics/blas_threads.hpp"
#include "produce/produce.hpp"
#include "yarn/rod/load_pattern.hpp"
#include "yarn/rod/material.hpp"

namespace yarnhom::yarn {
namespace {

// "index lower upper" per line (# comments): overrides of the sampling boxes. Every line that
// is not blank or a comment must be one; the box must hold 0 and stay where the strain means
// something (core/terms.hpp, strain_domain_violation).
std::map<int, Range> read_ranges(const std::string& path) {
  check_input_file(path, "--ranges");
  std::ifstream in(path);
  if (!in) throw FileError(path, "", "cannot open for reading");
  std::map<int, Range> out;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    line = line.substr(0, line.find('#'));
    std::istringstream ls(line);
    std::string a, b, c, extra;
    if (!(ls >> a)) continue;  // blank or comment
    const std::string where = "line " + std::to_string(lineno);
    double v[3];
    char* end = nullptr;
    if (!(ls >> b >> c) || (ls >> extra))
      throw FileError(path, where, "expected three fields 'index lower upper', got '" + line + "'");
    const std::string f[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      v[k] = std::strtod(f[k].c_str(), &end);
      if (end == f[k].c_str() || *end != '\0' || !std::isfinite(v[k]))
        throw FileError(path, where, "'" + f[k] + "' is not a finite number (expected 'index lower upper')");
    }
    const double idx = v[0], lo = v[1], hi = v[2];
    if (idx != int(idx) || idx < 0 || idx > 5 || idx == 4)
      throw FileError(path, where, "index must be one of 0 1 2 3 5 (s_x s_a s_y II_x II_y), got " + a);
    if (!(lo < 0 && hi > 0)) throw FileError(path, where, "need lower < 0 < upper");
    const int i = int(idx);
    for (double v : {lo, hi})
      if (std::string rule = strain_domain_violation(i, v); !rule.empty()) throw FileError(path, where, rule);
    if (out.count(i)) throw FileError(path, where, "index " + a + " given twice");
    out[i] = {lo, hi};
  }
  return out;
}

ProduceOptions produce_options(const ProduceRunOptions& o) {
  ProduceOptions opt;
  opt.preset = o.preset;
  points_per_axis(opt.preset, 1);  // refuse an unknown preset before any work
  opt.terms = parse_term_list(o.terms);
  // On MPI ranks the ranks are the parallelism: one thread each unless --threads says more
  // (every evaluation's sums are added in a fixed order, so the bits do not depend on it).
  // The BLAS (CHOLMOD's supernodal factorization of a large patch's Newton systems) runs on one
  // thread too unless OPENBLAS_NUM_THREADS says otherwise: OpenBLAS would start one per core in
  // every rank (or under every sector's thread) and oversubscribe the cores.
  opt.ranks = cluster::size() > 1;
  // Otherwise all cores, or OMP_NUM_THREADS where set (a rank of `mpirun ... study` sets it to
  // its share of the node for the stages it runs, pipeline/rank_tasks.hpp).
  opt.threads = o.threads > 0 ? o.threads : opt.ranks ? 1 : omp_get_max_threads();
  if (opt.ranks) omp_set_num_threads(opt.threads);
  if (!std::getenv("OPENBLAS_NUM_THREADS")) numerics::set_blas_threads(1);
  opt.sectors = o.sectors;
  opt.branch_rounds = o.branch_rounds;
  opt.branch_tolerance = o.branch_tolerance;
  opt.rest_time_limit = o.rest_time_limit;
  opt.warm_start = !o.no_warm;
  opt.predictor = !o.no_predictor;
  opt.free_period = !o.fixed_period;
  std::tie(opt.tiles_x, opt.tiles_y) = parse_tiles(o.tile, "--tile");
  if (!o.material.empty()) opt.material = load_material(o.material);
  if (!o.ranges.empty()) opt.ranges = read_ranges(o.ranges);
  opt.checkpoint = o.out + ".partial";
  return opt;
}

// Progress lines on stderr: redrawn in place on a terminal (5 a second), else every 10 s. The
// ETA is that of the pass it names: the node pass, then each round of the branch pass (whose
// number of rounds is not known in advance: they go on while nodes move to a lower branch;
// the README demo's took 2.5x the node pass in 12 rounds), so the line says which.
void add_progress(ProduceOptions& opt, const std::string& name) {
  const bool tty = stderr_is_tty();
  // Off a terminal every 10 s, or as often as YARNHOM_PROGRESS_SECONDS says (pipeline/
  // stage_runner.cpp sets 1 when it relays a stage's log to a terminal).
  const char* every_env = std::getenv("YARNHOM_PROGRESS_SECONDS");
  const double every = tty ? 0.2 : every_env && std::atof(every_env) > 0 ? std::atof(every_env) : 10.0;
  auto last = std::make_shared<double>(-1), last_branch = std::make_shared<double>(-1);
  // The round being reported, the elapsed time when it started, and that of the latest call.
  auto round = std::make_shared<std::array<double, 3>>(std::array<double, 3>{0, 0, -1});
  opt.progress = [=](int done, int total, int failed, double el) {
    if (el - *last < every && done < total) return;
    *last = el;
    const double eta = done > 0 ? el / done * (total - done) : 0;
    std::fprintf(stderr, "%sproduce %s: node pass ETA %s, %d/%d nodes, %d failed, %s elapsed; the branch pass follows%s",
                 tty ? "\r" : "", name.c_str(), format_seconds(eta).c_str(), done, total, failed,
                 format_seconds(el).c_str(), tty ? "   " : "\n");
    if (tty && done == total) std::fprintf(stderr, "\n");
  };
  opt.branch_progress = [=](int r, int done, int total, int moved, double el) {
    auto& [cur, start, prev] = *round;
    if (r != int(cur)) cur = r, start = prev >= 0 ? prev : el;  // a round starts where the last call left
    prev = el;
    if (el - *last_branch < every && done < total) return;
    *last_branch = el;
    const double in_round = el - start;
    const double eta = done > 0 ? in_round / done * (total - done) : 0;
    std::fprintf(stderr,
                 "%sproduce %s: branch pass round %d ETA %s, %d/%d nodes tried, %d moved to a lower branch, %s elapsed "
                 "(rounds go on while nodes move)%s",
                 tty ? "\r" : "", name.c_str(), r, format_seconds(eta).c_str(), done, total, moved,
                 format_seconds(el).c_str(), tty ? "   " : "\n");
    if (tty && done == total) std::fprintf(stderr, "\n");
  };
}

void print_rest(const Dataset& ds, const ProduceReport& rep) {
  std::printf("rest        %s, Psi0 %.10g J/m^2\n", rep.rest.summary().c_str(), ds.psi0);
  std::printf("period      %s %.6g x %.6g m; reference (%.6g, %.6g) (%.6g, %.6g) m; areal density %.6g kg/m^2\n",
              ds.rve_tiles.empty() ? "pattern" : "patch", ds.lattice_original[0], ds.lattice_original[3],
              ds.lattice_relaxed[0], ds.lattice_relaxed[1], ds.lattice_relaxed[2], ds.lattice_relaxed[3],
              ds.areal_density);
  std::printf("at rest     dPsi/ds %.3g %.3g %.3g (in-plane), dPsi/dII %.6g %.6g %.6g J/m (natural bending moment)\n",
              ds.grad0[0], ds.grad0[1], ds.grad0[2], ds.grad0[3], ds.grad0[4], ds.grad0[5]);
  const RestHessian& h = rep.rest_hessian;
  if (h.ok) {
    const ScaledEigen se = scaled_eigen(h.H);
    std::printf("rest Hessian d2Psi/ds2 diagonal %.4g %.4g %.4g (in-plane) %.4g %.4g %.4g (bending); %s, smallest "
                "scaled eigenvalue %.3g; asymmetry %.1e (%d solves, %.2f s)\n",
                h.H(0, 0), h.H(1, 1), h.H(2, 2), h.H(3, 3), h.H(4, 4), h.H(5, 5), se.stable() ? "stable" : "UNSTABLE",
                se.values[0], h.asymmetry, h.solves, h.seconds);
  } else {
    std::fprintf(stderr, "yarnhom: warning: the rest Hessian was not measured (%s); the dataset has none and the "
                         "training falls back to the grid's curvature at rest\n", h.failure.c_str());
  }
}

// On MPI ranks: where each rank's time went (why not N times faster?). A rank's busy time is
// its first-pass tasks' and its branch jobs' (those solved ahead of their round included, some
// while the first pass still ran); its idle time is the two passes' wall time less that.
void print_ranks(const ProduceReport& rep) {
  if (rep.rank_load.empty()) return;
  const double wall = rep.node_pass_seconds + rep.branch_pass_seconds;
  auto pct = [wall](double s) { return wall > 0 ? 100 * s / wall : 0.0; };
  double node = 0, branch = 0, lost = 0;
  for (const RankLoad& l : rep.rank_load) node += l.node_busy, branch += l.branch_busy, lost += l.ahead_lost;
  const double n = double(rep.rank_load.size());
  std::printf("ranks       %zu: node pass %.1f s + branch pass %.1f s wall (bounds whatever the ranks: the longest chain "
              "of warm starts %.1f s, the rounds' longest solves %.1f s); the ranks busy %.0f %% of it (node tasks %.0f %%, "
              "branch solves %.0f %%, of which %.0f %% solved ahead in vain); %d branch jobs solved ahead of their round, "
              "%d used; coordinator thread %.1f s CPU\n",
              rep.rank_load.size(), rep.node_pass_seconds, rep.branch_pass_seconds, rep.node_critical_seconds,
              rep.branch_critical_seconds, pct((node + branch) / n), pct(node / n), pct(branch / n), pct(lost / n),
              rep.ahead_solved, rep.ahead_used, rep.coordinator_cpu_seconds);
  for (size_t r = 0; r < rep.rank_load.size(); ++r) {
    const RankLoad& l = rep.rank_load[r];
    std::printf("  rank %-4zu %4d tasks %8.1f s, %5d branch solves %8.1f s (%.1f s in vain); busy %3.0f %%, idle %7.1f s\n",
                r, l.tasks, l.node_busy, l.jobs, l.branch_busy, l.ahead_lost, pct(l.node_busy + l.branch_busy),
                std::max(0.0, wall - l.node_busy - l.branch_busy));
  }
}

void print_terms(const ProduceOptions& opt, const ProduceReport& rep, const Pattern& p, const std::string& out) {
  if (rep.resumed)
    std::printf("resumed     %d samples with their equilibrium states from %s%s\n", rep.resumed, opt.checkpoint.c_str(),
                rep.checkpoint_dropped_bytes ? (" (its last record, cut by the kill: " + std::to_string(rep.checkpoint_dropped_bytes) +
                                                " bytes, removed and solved again)").c_str()
                                             : "");
  if (!rep.checkpoint_error.empty())
    std::fprintf(stderr, "yarnhom: warning: the checkpoint stopped being written (%s); the dataset is complete, but a "
                 "run killed then would have started over\n", rep.checkpoint_error.c_str());
  // "branches": grid edges whose energies and gradients disagree by more than the tolerance
  // (two equilibrium branches side by side), as first solved -> in the dataset; "worst" is the
  // largest mismatch left, relative to the term's typical edge change (produce/branch_check.hpp).
  std::printf("%-5s %6s %7s %10s %9s %9s %17s %6s %7s\n", "term", "nodes", "failed", "mean iter", "solve s", "cpu s",
              "branches", "moved", "worst");
  for (const auto& t : rep.terms) {
    char br[32];
    std::snprintf(br, sizeof br, "%d -> %d /%d", t.inconsistent_before, t.inconsistent_after, t.edges);
    std::printf("%-5s %6d %7d %10.1f %9.2f %9.2f %17s %6d %6.0f%%\n", t.name.c_str(), t.nodes, t.failed,
                t.mean_iterations, t.seconds, t.cpu_seconds, br, t.moved, 100 * t.worst_after);
  }
  std::printf("branches    edges whose energies and gradients disagree by more than %g of the term's typical edge "
              "change (trapezoid rule), as first solved -> after %d branch round(s) (docs/produce.md)\n",
              opt.branch_tolerance, rep.branch_rounds);
  std::printf("total       %.1f s wall, %.1f s in solves (%.1f s CPU)\n", rep.seconds, rep.solve_seconds,
              rep.solve_cpu_seconds);
  print_ranks(rep);
  std::printf("topology    every stored node certified: no yarn segment pair within d_min = %.3g x 2r along its "
              "path; closest centrelines %.4g x 2r%s\n",
              RveOptions{}.barrier_dmin, rep.min_separation / (2 * p.radius),
              rep.refused ? (", " + std::to_string(rep.refused) + " node(s) refused").c_str() : "");
  std::printf("dataset     %s\n", out.c_str());
}

}  // namespace

int run_produce(const ProduceRunOptions& o) {
  // Under mpirun only rank 0 writes (the dataset, the checkpoint) and prints; the other ranks
  // solve what it sends them (docs/produce.md, "On a cluster").
  const bool root = cluster::rank() == 0;
  const std::vector<std::string> inputs = {o.pattern, o.material, o.ranges};
  if (root) {
    // Before any work: the dataset and the checkpoint beside it must be writable and must not
    // be an input (the pattern, the material or the ranges file).
    prepare_output(o.out, inputs);
    check_output_file(o.out + ".partial", inputs, "-o (its checkpoint)");
  }
  const Pattern p = load_pattern(o.pattern);
  ProduceOptions opt = produce_options(o);
  if (!root) {
    produce(p, opt);
    return 0;
  }
  add_progress(opt, p.name);
  const std::string start = !opt.warm_start ? "no warm start" : opt.predictor ? "warm start with predictor" : "warm start, no predictor";
  const std::string where = opt.ranks ? std::to_string(cluster::size()) + " MPI ranks (each solves, rank 0 also "
                                            "coordinates; " + std::to_string(opt.threads) + " thread(s) each)"
                                      : std::to_string(opt.threads) + " threads";
  const std::string rve = opt.tiles_x * opt.tiles_y > 1
                              ? ", RVE " + std::to_string(opt.tiles_x) + " x " + std::to_string(opt.tiles_y) + " tiles"
                              : "";
  std::printf("produce %s -> %s (preset %s, %zu terms, %s, %s%s)\n", p.name.c_str(), o.out.c_str(), o.preset.c_str(),
              opt.terms.size(), where.c_str(), start.c_str(), rve.c_str());
  ProduceReport rep;
  const Dataset ds = produce(p, opt, &rep);
  write_dataset(o.out, ds);
  print_rest(ds, rep);
  print_terms(opt, rep, p, o.out);
  if (!rep.failures.empty()) {
    std::fprintf(stderr, "yarnhom: error: %zu nodes did not converge with a valid topology certificate (warm, by continuation from "
                 "the parent, cold, by continuation from rest); they are not in the dataset:\n",
                 rep.failures.size());
    for (const auto& f : rep.failures) {
      std::fprintf(stderr, "  term %s at s =", f.term.c_str());
      for (int k = 0; k < 6; ++k) std::fprintf(stderr, " %g", f.s[k]);
      std::fprintf(stderr, ": %s\n", f.status.c_str());
    }
    return 3;
  }
  std::filesystem::remove(opt.checkpoint);
  return 0;
}

}  // namespace yarnhom::yarn
