// The nodes of a produce() run and the checkpoint it resumes from (produce/produce_pass.hpp).
#include <algorithm>
#include <string>

#include "core/error.hpp"
#include "produce/produce_pass.hpp"

namespace yarnhom::yarn {

void make_nodes(ProduceRun& run) {
  const ProduceOptions& opt = run.opt;
  run.term_nodes_idx.assign(opt.terms.size(), {});
  for (size_t ti = 0; ti < opt.terms.size(); ++ti) {
    const Term& t = opt.terms[ti];
    std::vector<Range> box;
    for (int i : t.indices) box.push_back(pattern_range(run.pattern.name, i, opt.ranges));
    const auto pts = term_nodes(t, box, points_per_axis(opt.preset, t.dim()));
    for (size_t k = 0; k < pts.size(); ++k) {
      ProduceNode n;
      n.term = static_cast<int>(ti);
      n.index = static_cast<int>(k);
      n.t = pts[k];
      n.s = Strain::Zero();
      for (int d = 0; d < t.dim(); ++d) n.s[t.indices[d]] = pts[k][d];
      if (n.t.norm() == 0) {  // the origin is the rest state
        n.done = true;
        n.psi = n.psi1 = run.r0.psi;
        n.grad = n.grad1 = run.r0.grad;
        n.status = "converged";
      }
      run.term_nodes_idx[ti].push_back(static_cast<int>(run.nodes.size()));
      run.nodes.push_back(std::move(n));
    }
  }
}

namespace {

// Branch records after the last recorded round end belong to a round the kill cut short:
// they are dropped (and cut from the file), and that round runs again from its start.
void drop_unfinished_round(CheckpointContents& cc) {
  size_t keep = cc.records.size();
  for (size_t k = cc.records.size(); k-- > 0;) {
    if (cc.records[k].status == kBranchRound) break;
    if (cc.records[k].status == kLowerBranch) keep = k;
  }
  if (keep < cc.records.size()) {
    cc.dropped_bytes += cc.valid_bytes - cc.records[keep].offset;
    cc.valid_bytes = cc.records[keep].offset;
    cc.records.resize(keep);
  }
}

// A node moved to a lower branch by a resumed round.
void apply_branch_record(const ProduceRun& run, const CheckpointRecord& rec, size_t k, ProduceNode& n) {
  if (!n.done || n.status != "converged" || !rec.has_state)
    throw FileError(run.opt.checkpoint, "", "a branch record of node " + std::to_string(rec.index) + " of term " +
                                                std::to_string(rec.term) + " before its first solve; remove it to start over");
  n.psi = rec.psi;
  n.grad = rec.grad;
  n.iterations = rec.iterations;
  n.seconds = rec.seconds;
  n.cpu_seconds = rec.cpu_seconds;
  n.min_separation = rec.min_distance;
  n.branch_record = static_cast<int>(k);
  n.moved = true;
}

// A node's first solve, resumed (failures are tried again).
void apply_node_record(ProduceRun& run, const CheckpointRecord& rec, size_t k, ProduceNode& n) {
  if (n.done || rec.status != "converged") return;
  if (run.opt.warm_start && !rec.has_state)
    throw FileError(run.opt.checkpoint, "", "a converged sample without its state in a warm-started run; remove it to start over");
  n.done = n.resumed = true;
  n.status = rec.status;
  n.iterations = rec.iterations;
  n.seconds = rec.seconds;
  n.cpu_seconds = rec.cpu_seconds;
  n.psi = n.psi1 = rec.psi;
  n.grad = n.grad1 = rec.grad;
  n.record = static_cast<int>(k);
  n.min_separation = rec.min_distance;
  ++run.rep.resumed;
}

}  // namespace

void resume_checkpoint(ProduceRun& run, const std::string& fingerprint) {
  const ProduceOptions& opt = run.opt;
  const std::string rest_sig = rest_signature(run.r0.psi, run.rest());
  CheckpointContents& cc = run.cc;
  cc = read_checkpoint(opt.checkpoint, fingerprint, rest_sig, run.rest());
  drop_unfinished_round(cc);
  for (size_t k = 0; k < cc.records.size(); ++k) {
    const CheckpointRecord& rec = cc.records[k];
    if (rec.status == kBranchRound) {
      run.rep.branch_rounds = std::max(run.rep.branch_rounds, rec.index);
      continue;
    }
    if (rec.term < 0 || rec.term >= int(opt.terms.size()) || rec.index < 0 ||
        rec.index >= int(run.term_nodes_idx[rec.term].size()))
      throw FileError(opt.checkpoint, "", "a record of node " + std::to_string(rec.index) + " of term " +
                                              std::to_string(rec.term) + ", which this run does not have; remove it to start over");
    ProduceNode& n = run.nodes[run.term_nodes_idx[rec.term][rec.index]];
    if (rec.status == kLowerBranch) apply_branch_record(run, rec, k, n);
    else apply_node_record(run, rec, k, n);
  }
  run.rep.checkpoint_dropped_bytes = cc.dropped_bytes;
  run.ck = open_checkpoint(opt.checkpoint, fingerprint, rest_sig, &cc);
}

}  // namespace yarnhom::yarn
