#include "produce/produce.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "core/cluster.hpp"
#include "produce/produce_pass.hpp"

namespace yarnhom::yarn {

int points_per_axis(const std::string& preset, int dim) {
  if (preset == "quick") return dim == 1 ? 21 : 9;
  if (preset == "paper") return dim == 1 ? 101 : 31;
  if (preset == "tiny") return dim == 1 ? 5 : 3;  // for tests
  throw std::invalid_argument("unknown preset '" + preset + "' (known: quick, paper)");
}

Range pattern_range(const std::string& pattern, int index, const std::map<int, Range>& overrides) {
  auto it = overrides.find(index);
  if (it != overrides.end()) return it->second;
  double bx = 200, by = 200;
  if (pattern == "stockinette") bx = 200, by = 230;
  else if (pattern == "basket") bx = by = 170;
  else if (pattern == "slip_stitch_honeycomb") bx = by = 120;
  else if (pattern == "cartridge_belt_rib") bx = 100, by = 80;
  return default_range(index, bx, by);
}

namespace {

std::string fingerprint(const Pattern& p, const ProduceOptions& opt) {
  std::ostringstream f;
  f.precision(17);
  // "contact=barrier-ccd": samples of runs before the collision filter and certificate are not
  // resumed (they may hold states with yarns passed through each other). The sectors and the
  // warm-start mode decide which state each node starts from: a resumed run must share them.
  f << p.name << " n=" << p.size() << " preset=" << opt.preset << " tol=" << opt.solve.tolerance
    << " rest=" << (opt.free_period ? "stress-free" : "pattern-period") << " contact=barrier-ccd height=mean"
    << " sectors=" << std::max(1, opt.sectors)
    << " start=" << (!opt.warm_start ? "cold" : opt.predictor ? "warm+predictor" : "warm")
    << " branch=" << (opt.warm_start ? opt.branch_rounds : 0) << "/" << opt.branch_tolerance << "/direct40";
  if (opt.tiles_x * opt.tiles_y > 1) f << " rve=" << opt.tiles_x << "x" << opt.tiles_y;
  for (const auto& t : opt.terms) f << " " << t.name;
  for (int i = 0; i < 6; ++i) {
    const Range r = pattern_range(p.name, i, opt.ranges);
    f << " [" << r.lower << "," << r.upper << "]";
  }
  std::string m = format_material(opt.material);
  for (char& c : m)
    if (c == '\n') c = ';';
  return f.str() + " " + m;
}

// The rest state: the origin of every sector, and Psi0. With free_period the tile's period
// relaxes too and the RVE's reference is the relaxed tile (s = 0 stress free).
RestTile rest_tile(const Pattern& pattern, const ProduceOptions& opt) {
  RestOptions rest_opt;
  rest_opt.free_period = opt.free_period;
  rest_opt.solve = opt.solve;
  rest_opt.solve.sensitivity_directions.clear();
  rest_opt.max_seconds = opt.rest_time_limit;
  if (opt.tiles_x < 1 || opt.tiles_y < 1 || opt.tiles_x > 64 || opt.tiles_y > 64)
    throw std::invalid_argument("produce: the RVE's tiles must be 1..64 in each direction, got " +
                                std::to_string(opt.tiles_x) + " x " + std::to_string(opt.tiles_y));
  try {
    // A patch keeps one tile's rest: the same Psi0 and a stress-free s = 0.
    return repeat_rest(pattern, relax_tile(pattern, opt.material, rest_opt), opt.tiles_x, opt.tiles_y);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string("produce: ") + e.what());
  }
}

}  // namespace

CheckpointRecord record_of(const ProduceNode& n, const std::string& status) {
  CheckpointRecord rec;
  rec.term = n.term;
  rec.index = n.index;
  rec.iterations = n.iterations;
  rec.seconds = n.seconds;
  rec.cpu_seconds = n.cpu_seconds;
  rec.status = status;
  rec.psi = n.psi;
  rec.grad = n.grad;
  rec.min_distance = n.min_separation;
  return rec;
}

ProduceRun::ProduceRun(const Pattern& p, const ProduceOptions& o, RestTile t)
    : pattern(p), opt(o), tile(std::move(t)), threads(std::max(1, o.threads)), t0(std::chrono::steady_clock::now()) {}

double ProduceRun::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void ProduceRun::append(const CheckpointRecord& rec) {
  if (!ck) return;
  try {
    append_checkpoint(ck, opt.checkpoint, rec, rest());
  } catch (const std::exception& e) {
    checkpoint_error = e.what();
    std::fclose(ck);
    ck = nullptr;
  }
}

Dataset produce(const Pattern& pattern, const ProduceOptions& opt, ProduceReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  ProduceRun run(pattern, opt, rest_tile(pattern, opt));
  run.t0 = t0;
  ProduceReport& rep = run.rep;
  rep.rest = run.tile.report;
  if (!run.rest().certificate.valid)
    throw std::runtime_error("produce: pattern '" + pattern.name + "': " + summary(run.rest().certificate, 2 * pattern.radius));
  rep.min_separation = run.rest().certificate.min_distance;
  run.r0 = evaluate_density(run.rve(), Strain::Zero(), run.rest());
  // The curvature of Psi at rest, which the grid does not resolve (yarn/rve/rest_hessian.hpp): 12
  // small solves from the rest state, measured again on a resumed run (it is cheap and
  // deterministic). On MPI ranks rank 0 measures it after the passes, when nothing waits on it.
  const bool ranks = opt.ranks && cluster::size() > 1;
  if (!ranks) rep.rest_hessian = rest_hessian(run.rve(), run.rest(), opt.solve);
  make_nodes(run);
  if (ranks && cluster::rank() != 0) {
    cluster_work(run);
    if (report) *report = rep;
    return Dataset{};
  }
  if (!opt.checkpoint.empty()) resume_checkpoint(run, fingerprint(pattern, opt));
  if (ranks) {
    cluster_coordinate(run);
    rep.rest_hessian = rest_hessian(run.rve(), run.rest(), opt.solve);
  } else {
    first_pass(run);
    branch_pass(run);
  }
  if (run.ck) std::fclose(run.ck);
  rep.checkpoint_error = run.checkpoint_error;
  Dataset ds = assemble_dataset(run);
  rep.seconds = run.elapsed();
  if (report) *report = rep;
  return ds;
}

}  // namespace yarnhom::yarn
