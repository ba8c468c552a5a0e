#include "bake/bake_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/jet_layout.hpp"

namespace yarnhom {

BakedTable bake_function(const Term& term, const std::vector<double>& lower,
                         const std::vector<double>& upper, const std::vector<int>& knots,
                         const TermFunction& f, BakeReport* report, bool repair, const double* min_curvature) {
  const int d = term.dim();
  if (lower.size() != size_t(d) || upper.size() != size_t(d) || knots.size() != size_t(d))
    throw std::invalid_argument("bake '" + term.name + "': box or knot counts of the wrong size");
  for (int k = 0; k < d; ++k) {
    if (knots[k] < 2) throw std::invalid_argument("bake '" + term.name + "': need at least 2 knots per axis");
    if (!(lower[k] < upper[k])) throw std::invalid_argument("bake '" + term.name + "': empty box");
  }
  BakedTable t;
  t.term = term;
  t.lower = lower;
  t.upper = upper;
  t.knots = knots;
  const int n = static_cast<int>(t.num_knots());
  std::vector<double> s(size_t(n) * d);
  if (d == 1) {
    for (int i = 0; i < n; ++i) s[i] = knot_position(lower[0], upper[0], n, i);
    // Order 1 is all the cubic Hermite table stores.
    auto jet = f(s.data(), n, 1);
    t.f.assign(jet.begin(), jet.begin() + n);
    t.f_x.assign(jet.begin() + n, jet.begin() + 2 * n);
  } else {
    const int n0 = knots[0], n1 = knots[1];
    for (int i = 0; i < n0; ++i)
      for (int j = 0; j < n1; ++j) {
        s[2 * (size_t(i) * n1 + j)] = knot_position(lower[0], upper[0], n0, i);
        s[2 * (size_t(i) * n1 + j) + 1] = knot_position(lower[1], upper[1], n1, j);
      }
    // Order 2 for the mixed derivative f_xy, channel jet_ch2(2, 0, 1).
    auto jet = f(s.data(), n, 2);
    auto channel = [&](int c) { return std::vector<double>(jet.begin() + size_t(c) * n, jet.begin() + size_t(c + 1) * n); };
    t.f = channel(0);
    t.f_x = channel(1);
    t.f_y = channel(2);
    t.f_xy = channel(jet_ch2(2, 0, 1));
  }
  BakeReport rep;
  if (repair) rep.repair = repair_boundary(t, min_curvature);
  compute_safeguard(t, &rep.departures);
  if (report) *report = rep;
  return t;
}

BakedTable bake_network(const ModelNetwork& net, int res1d, int res2d, BakeReport* report, bool repair,
                        const double* min_curvature) {
  const int d = net.term.dim();
  std::vector<int> knots(d, d == 1 ? res1d : res2d);
  BakedTable t = bake_function(net.term, net.lower, net.upper, knots, material_function(net), report, repair,
                               min_curvature);
  t.desc = net.desc;
  t.norm = net.norm;
  t.epochs = net.epochs;
  t.backend = net.backend;
  t.status = net.status;
  return t;
}

BakedModel bake_model(const Model& model, const std::string& model_path, int res1d, int res2d,
                      double psi0, bool psi0_known, std::vector<BakeReport>* reports) {
  BakedModel b;
  b.model = model_path;
  b.dataset = model.dataset;
  b.psi0 = psi0;
  b.psi0_known = psi0_known;
  b.areal_density = model.areal_density;
  std::vector<BakeReport> rep(model.networks.size());
  for (size_t k = 0; k < model.networks.size(); ++k) b.tables.push_back(bake_network(model.networks[k], res1d, res2d, &rep[k]));
  auto index_1d = [&](int strain) -> int {
    for (size_t k = 0; k < b.tables.size(); ++k)
      if (b.tables[k].dim() == 1 && b.tables[k].term.indices[0] == strain) return int(k);
    return -1;
  };
  // Curvature floors: per 1D table and end, from the most negative total outward slope of every
  // pair whose box shares that end.
  std::vector<std::array<double, 2>> floors(b.tables.size(), {0.0, 0.0});
  {
    const std::vector<PairCheck> pcs = check_pairs(b);
    for (size_t k = 0; k < b.tables.size(); ++k) {
      const BakedTable& t2 = b.tables[k];
      if (t2.dim() != 2 || t2.extrapolation == kBakedLinear) continue;
      const int one[2] = {index_1d(t2.term.indices[0]), index_1d(t2.term.indices[1])};
      const PairCheck& pc = pcs[k];
      for (int axis = 0; axis < 2; ++axis) {
        if (one[axis] < 0) continue;
        const BakedTable& t1 = b.tables[one[axis]];
        const double W = t1.upper[0] - t1.lower[0];
        for (int e = 0; e < 2; ++e) {
          const double X2 = e ? t2.upper[axis] : t2.lower[axis], X1 = e ? t1.upper[0] : t1.lower[0];
          const double S = pc.worst_slope[2 * axis + e];
          if (std::abs(X2 - X1) > 1e-9 * W || !(S < 0)) continue;
          const double K = -S / (kSlopeRecoveryFraction * W);
          if (K > floors[one[axis]][e]) {
            floors[one[axis]][e] = K;
            rep[one[axis]].floor_pair[e] = t2.term.name;
          }
        }
      }
    }
  }
  for (size_t k = 0; k < b.tables.size(); ++k)
    if (floors[k][0] > 0 || floors[k][1] > 0) {
      const auto pairs = rep[k].floor_pair;
      b.tables[k] = bake_network(model.networks[k], res1d, res2d, &rep[k], true, floors[k].data());
      rep[k].floor_pair = pairs;
    }
  // The 1D tables are final: the 2D corners are repaired against them.
  std::vector<BakedTerm> one_d;
  for (const BakedTable& t : b.tables)
    if (t.dim() == 1) one_d.push_back(make_baked_term(t));
  if (reports) *reports = rep;
  for (size_t k = 0; k < b.tables.size(); ++k) {
    BakedTable& t = b.tables[k];
    if (t.dim() != 2) continue;
    const BakedTerm* ti = find_one_d(one_d, t.term.indices[0]);
    const BakedTerm* tj = find_one_d(one_d, t.term.indices[1]);
    const CornerTwistRepair r = repair_corner_twists(t, ti, tj);
    // After the corners: the edge repair keeps their twists and lifts the corner knots' slopes.
    const EdgeSlopeRepair es = repair_edge_slopes(t, ti, tj);
    if (reports) {
      (*reports)[k].corners = r;
      (*reports)[k].edges = es;
    }
  }
  if (reports) {
    const std::vector<PairCheck> pairs = check_pairs(b);
    for (size_t k = 0; k < pairs.size(); ++k) (*reports)[k].pair = pairs[k];
  }
  return b;
}

}  // namespace yarnhom

namespace yarnhom {

std::string BakeReport::summary(const BakedTable& t) const {
  static const char* k1d[2] = {"lower end", "upper end"};
  std::string out;
  char buf[256];
  auto add = [&](const std::string& s) { out += (out.empty() ? "" : "; ") + s; };
  const bool one = t.dim() == 1;
  for (size_t k = 0; k < repair.sides.size(); ++k) {
    const SideRepair& r = repair.sides[k];
    const char* name = k1d[k];  // only 1D tables are repaired
    if (r.repaired) {
      std::snprintf(buf, sizeof buf, "%s: inward slope raised to 0 (by %.3g)", name, r.max_slope_raise);
      add(buf);
    }
    if (r.curvature_raised && !r.floor_raised) add(std::string(name) + ": negative curvature raised to 0 in the table");
    if (r.floor_raised) {
      std::snprintf(buf, sizeof buf, "%s: curvature raised to %.3g in the table (pair %s's total falls outward there: it "
                    "now turns up within %.0f%% of the box width)", name, r.curvature_floor,
                    floor_pair[k].empty() ? "?" : floor_pair[k].c_str(), 100 * kSlopeRecoveryFraction);
      add(buf);
    }
  }
  if (repair.changed() && repair.max_change > 1e-12 * repair.range) {
    std::snprintf(buf, sizeof buf, "table changed in the outer %.0f%% by at most %.2g (%.2g%% of its range)",
                  100 * repair.layer_fraction, repair.max_change,
                  repair.range > 0 ? 100 * repair.max_change / repair.range : 0.0);
    add(buf);
  }
  if (one) {
    for (size_t k = 0; k < departures.sides.size(); ++k)
      if (departures.sides[k].curvature_raised) add(std::string(k1d[k]) + ": negative curvature continued as 0");
  } else if (departures.first_order) {
    // Every 2D table departs the same way: the boundary curvature is not continued.
    int neg = 0, knots = 0;
    double dropped = 0;
    for (const SafeguardDepartures::Side& d : departures.sides) {
      neg += d.curvature_raised;
      knots += d.knots;
      dropped = std::max(dropped, d.curvature_dropped);
    }
    if (dropped > 0) {
      std::snprintf(buf, sizeof buf, "first order outside (boundary curvature up to %.3g dropped; negative at %d of %d "
                    "edge knots)", dropped, neg, knots);
      add(buf);
    }
  }
  if (corners.any()) add(corners.summary());
  if (edges.any()) add(edges.summary());
  const std::string pair_note = pair.summary();
  if (!pair_note.empty()) add("REPORT: " + pair_note);
  return out.empty() ? "the paper's continuation" : out;
}

}  // namespace yarnhom
