// The dataset of a produce() run (spec section 3 targets) and its terms' summaries
// (produce_pass.hpp).
#include <algorithm>
#include <sstream>
#include <string>

#include "produce/produce_pass.hpp"

namespace yarnhom::yarn {

namespace {

// What the dataset says of the rest state, the RVE and the run.
void dataset_header(const ProduceRun& run, Dataset& ds) {
  const ProduceOptions& opt = run.opt;
  const Pattern& pattern = run.pattern;
  const int copies = opt.tiles_x * opt.tiles_y;
  ds.pattern = pattern.name;
  ds.source = "yarn-rve";
  ds.psi0 = run.r0.psi;
  ds.rest_q.resize(run.rest().packed().size());
  Eigen::VectorXd::Map(ds.rest_q.data(), ds.rest_q.size()) = run.rest().packed();
  const Eigen::Matrix2d L = run.rve().lattice();
  ds.lattice_original = {pattern.px * opt.tiles_x, 0.0, 0.0, pattern.py * opt.tiles_y};
  if (copies > 1) ds.rve_tiles = {double(opt.tiles_x), double(opt.tiles_y)};
  ds.lattice_relaxed = {L(0, 0), L(1, 0), L(0, 1), L(1, 1)};
  ds.grad0.assign(run.r0.grad.data(), run.r0.grad.data() + 6);
  if (run.rep.rest_hessian.ok)  // symmetric: its storage order is row-major as well
    ds.rest_hessian.assign(run.rep.rest_hessian.H.data(), run.rep.rest_hessian.H.data() + 36);
  ds.areal_density = areal_density(run.rve());
  std::ostringstream note;
  note.precision(9);
  note << "yarnhom produce, preset " << opt.preset << ", " << (opt.warm_start ? "warm start" : "cold start")
       << (copies > 1 ? "; RVE: " + std::to_string(opt.tiles_x) + " x " + std::to_string(opt.tiles_y) + " tiles" : "")
       << "; rest: " << (opt.free_period ? "stress-free tile, relaxed from the pattern's period by (s_x, s_a, s_y) = ("
                                         : "the pattern's period, pre-stressed (")
       << run.tile.report.strain[0] << ", " << run.tile.report.strain[1] << ", " << run.tile.report.strain[2]
       << "); material: " << format_material(opt.material);
  ds.note = note.str();
}

bool converged(const ProduceNode& n) { return n.status == "converged"; }

// A term's nodes: counts, times, failures, and the branch pass's edges.
TermSummary term_summary(ProduceRun& run, size_t ti) {
  const Term& t = run.opt.terms[ti];
  TermSummary sum;
  sum.name = t.name;
  const auto& ids = run.term_nodes_idx[ti];
  int iters = 0;
  for (int id : ids) {
    const ProduceNode& n = run.nodes[id];
    ++sum.nodes;
    if (n.resumed) ++sum.resumed;
    sum.seconds += n.seconds;
    sum.cpu_seconds += n.cpu_seconds;
    iters += n.iterations;
    if (!converged(n)) {
      ++sum.failed;
      run.rep.failures.push_back({t.name, n.s, n.status});
    }
  }
  sum.mean_iterations = sum.nodes ? double(iters) / sum.nodes : 0;
  const auto before = term_edges(run, ti, true).first, after = term_edges(run, ti, false).first;
  sum.edges = static_cast<int>(after.size());
  sum.inconsistent_before = static_cast<int>(inconsistent_edges(before, run.opt.branch_tolerance).size());
  sum.inconsistent_after = static_cast<int>(inconsistent_edges(after, run.opt.branch_tolerance).size());
  for (const GridEdge& e : after) sum.worst_after = std::max(sum.worst_after, e.relative);
  for (int id : ids) sum.moved += run.nodes[id].moved;
  return sum;
}

// A term's samples: 1D, Psi - Psi0 and the gradient; 2D, the coupling left after the two axis
// terms (the grid is row-major: node (i, j) has a = axis_a[i], b = axis_b[j]; its axis nodes
// are (i, j0) and (i0, j) with j0, i0 the positions of 0).
TermData term_data(const ProduceRun& run, size_t ti) {
  const Term& t = run.opt.terms[ti];
  const double psi0 = run.r0.psi;
  TermData td;
  td.term = t;
  for (int i : t.indices) {
    const Range r = pattern_range(run.pattern.name, i, run.opt.ranges);
    td.lower.push_back(r.lower);
    td.upper.push_back(r.upper);
  }
  const auto& ids = run.term_nodes_idx[ti];
  const auto& nodes = run.nodes;
  if (t.dim() == 1) {
    const int I = t.indices[0];
    for (int id : ids) {
      const ProduceNode& n = nodes[id];
      if (!converged(n)) continue;
      td.strain.push_back(n.t[0]);
      td.raw.push_back(n.psi - psi0);
      td.energy.push_back(n.psi - psi0);
      td.gradient.push_back(n.grad[I]);
    }
  } else {
    const int I = t.indices[0], J = t.indices[1];
    const int m = points_per_axis(run.opt.preset, 2);
    int i0 = -1, j0 = -1;
    for (int k = 0; k < m; ++k) {
      if (nodes[ids[k * m]].t[0] == 0) i0 = k;
      if (nodes[ids[k]].t[1] == 0) j0 = k;
    }
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        const ProduceNode& n = nodes[ids[i * m + j]];
        const ProduceNode& na = nodes[ids[i * m + j0]];  // (a, 0)
        const ProduceNode& nb = nodes[ids[i0 * m + j]];  // (0, b)
        if (!converged(n) || !converged(na) || !converged(nb)) continue;
        const double psi_a = na.psi - psi0, psi_b = nb.psi - psi0;
        td.strain.insert(td.strain.end(), {n.t[0], n.t[1]});
        td.raw.push_back(n.psi - psi0);
        td.energy.push_back(n.psi - psi0 - psi_a - psi_b);
        td.gradient.insert(td.gradient.end(), {n.grad[I] - na.grad[I], n.grad[J] - nb.grad[J]});
      }
  }
  td.n = static_cast<int>(td.energy.size());
  return td;
}

}  // namespace

Dataset assemble_dataset(ProduceRun& run) {
  Dataset ds;
  dataset_header(run, ds);
  ProduceReport& rep = run.rep;
  for (size_t ti = 0; ti < run.opt.terms.size(); ++ti) {
    const TermSummary sum = term_summary(run, ti);
    for (int id : run.term_nodes_idx[ti])
      if (converged(run.nodes[id])) rep.min_separation = std::min(rep.min_separation, run.nodes[id].min_separation);
    rep.solve_seconds += sum.seconds;
    rep.solve_cpu_seconds += sum.cpu_seconds;
    ds.terms.push_back(term_data(run, ti));
    rep.terms.push_back(sum);
  }
  return ds;
}

}  // namespace yarnhom::yarn
