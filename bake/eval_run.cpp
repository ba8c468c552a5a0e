#include "bake/eval_run.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "bake/term_function.hpp"
#include "core/baked.hpp"
#include "core/file_checks.hpp"
#include "core/jet_layout.hpp"
#include "core/model.hpp"
#include "core/number_list.hpp"
#include "material/baked_eval.hpp"

namespace yarnhom {
namespace {

// Reads strain points from a CSV file: one point per line, d numbers separated by commas;
// blank lines and lines starting with '#' are skipped, and a first line that is not numeric
// is taken as a header.
std::vector<double> read_points_csv(const std::string& path, int d) {
  check_input_file(path, "--points");
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open");
  std::vector<double> pts;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line[0] == '#') continue;
    std::vector<double> v;
    try {
      v = parse_numbers(line, path + ":" + std::to_string(lineno));
    } catch (const std::invalid_argument&) {
      if (pts.empty() && lineno == 1) continue;  // header
      throw;
    }
    if (int(v.size()) != d)
      throw std::invalid_argument(path + ":" + std::to_string(lineno) + ": expected " +
                                  std::to_string(d) + " numbers, found " + std::to_string(v.size()));
    pts.insert(pts.end(), v.begin(), v.end());
  }
  return pts;
}

// Column names: psi, then d<sym> for each derivative, e.g. d/ds_x, d2/ds_x/ds_y.
std::vector<std::string> channel_names(const Term& t) {
  const int d = t.dim();
  auto sym = [&](int i) { return std::string(kStrainSymbols[t.indices[i]]); };
  std::vector<std::string> names = {"psi"};
  for (int i = 0; i < d; ++i) names.push_back("d/d" + sym(i));
  for (int q = 0; q < jet_num_pairs(d); ++q) {
    JetPair e = jet_pair(d, q);
    names.push_back("d2/d" + sym(e.i) + "/d" + sym(e.j));
  }
  for (int q = 0; q < jet_num_triples(d); ++q) {
    JetTriple e = jet_triple(d, q);
    names.push_back("d3/d" + sym(e.i) + "/d" + sym(e.j) + "/d" + sym(e.k));
  }
  return names;
}

std::string point_text(const std::vector<double>& pts, int d, int p) {
  std::string at;
  char buf[32];
  for (int i = 0; i < d; ++i) {
    std::snprintf(buf, sizeof buf, "%s%.6g", i ? "," : "", pts[size_t(p) * d + i]);
    at += buf;
  }
  return at;
}

// The points of --at, then of --points, each checked.
std::vector<double> eval_points(const EvalOptions& o, const Term& term) {
  const int d = term.dim();
  std::vector<double> pts;
  for (const std::string& a : o.at) {
    auto v = parse_numbers(a, "--at");
    if (int(v.size()) != d)
      throw std::invalid_argument("--at " + a + ": term " + o.term + " needs " + std::to_string(d) + " value(s)");
    pts.insert(pts.end(), v.begin(), v.end());
  }
  if (!o.points.empty()) {
    auto v = read_points_csv(o.points, d);
    pts.insert(pts.end(), v.begin(), v.end());
  }
  if (pts.empty()) throw std::invalid_argument("no points: give --at or --points");
  // Any finite strain may be evaluated (the baked safeguard is defined everywhere, which is
  // worth looking at even where no cloth goes), but beyond 1e6 in any component nothing is a
  // strain or a curvature any more, and the network's or the safeguard's arithmetic overflows.
  const int n = int(pts.size()) / d;
  for (int p = 0; p < n; ++p)
    for (int i = 0; i < d; ++i)
      if (!(std::abs(pts[size_t(p) * d + i]) <= 1e6))
        throw std::invalid_argument("strain point " + point_text(pts, d, p) + " (point " + std::to_string(p + 1) +
                                    " of --at, then --points): " + kStrainSymbols[term.indices[i]] +
                                    " must lie within +-1e6");
  return pts;
}

void print_csv(const Term& term, const std::vector<double>& pts, const std::vector<double>& jet) {
  const int d = term.dim();
  const int n = int(pts.size()) / d;
  auto names = channel_names(term);
  for (int i = 0; i < d; ++i) std::printf("%s,", kStrainSymbols[term.indices[i]]);
  for (size_t c = 0; c < names.size(); ++c) std::printf("%s%s", names[c].c_str(), c + 1 < names.size() ? "," : "\n");
  for (int p = 0; p < n; ++p) {
    for (int i = 0; i < d; ++i) std::printf("%.17g,", pts[p * d + i]);
    for (size_t c = 0; c < names.size(); ++c)
      std::printf("%.17g%s", jet[c * n + p], c + 1 < names.size() ? "," : "\n");
  }
}

}  // namespace

void run_eval(const EvalOptions& o) {
  // A baked file answers from its table; a model file from its network.
  std::optional<Model> m;
  std::optional<BakedModel> bm;
  const ModelNetwork* net = nullptr;
  const BakedTable* table = nullptr;
  if (is_baked_file(o.model)) {
    bm = read_baked(o.model);
    table = bm->find(o.term);
    if (!table) throw std::invalid_argument(o.model + ": no table for term '" + o.term + "'");
  } else {
    m = read_model(o.model);
    net = m->find(o.term);
    if (!net) throw std::invalid_argument(o.model + ": no network for term '" + o.term + "'");
  }
  const Term& term = net ? net->term : table->term;
  const int d = term.dim();
  const std::vector<double> pts = eval_points(o, term);
  const int n = int(pts.size()) / d;
  const int C = jet_channels(d, 3);
  std::vector<double> jet;
  if (net) {
    jet = material_function(*net)(pts.data(), n, 3);  // what bake bakes (2D: the axis projection)
  } else {
    const BakedTerm bt = make_baked_term(*table, o.model);
    jet.resize(size_t(C) * n);
    double j[kMaxJetChannels];
    for (int p = 0; p < n; ++p) {
      eval_baked_jet(bt, &pts[size_t(p) * d], 3, j);
      for (int c = 0; c < C; ++c) jet[size_t(c) * n + p] = j[c];
    }
  }
  // A strain far outside any box (1e308) overflows the network or the safeguard: refuse
  // it, naming the point, rather than print inf or NaN with exit status 0.
  for (int p = 0; p < n; ++p)
    for (int c = 0; c < C; ++c)
      if (!std::isfinite(jet[size_t(c) * n + p]))
        throw std::invalid_argument("strain point " + point_text(pts, d, p) + " (point " + std::to_string(p + 1) +
                                    " of --at, then --points) gives a non-finite energy or derivative: it "
                                    "lies too far outside the term's box");
  print_csv(term, pts, jet);
}

}  // namespace yarnhom
