#include "material/hylc_material.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "material/baked_eval.hpp"
#include "core/atomic_file.hpp"
#include "core/jet_layout.hpp"
#include "io/json_reader.hpp"

namespace yarnhom {

namespace {

using json = io::json;

// ---------------------------------------------------------------------------------------
// Reading.

struct Reader : io::JsonReader {
  std::vector<double> knots(const json& j, const std::string& key) const {
    std::vector<double> t = numbers(j, key);
    if (t.size() < 2) fail(key, "needs at least 2 knots");
    for (size_t i = 1; i < t.size(); ++i)
      if (!(t[i] > t[i - 1])) fail(key, "knots must increase strictly (at index " + std::to_string(i) + ")");
    return t;
  }
  void sized(const std::vector<double>& v, size_t n, const std::string& key) const {
    if (v.size() != n) fail(key, "has " + std::to_string(v.size()) + " entries, expected " + std::to_string(n));
  }
  int ext(const json& j, const std::string& key) const { return j.contains("ext") ? index(j["ext"], key + ".ext", 0, 2) : 0; }
};

// ---------------------------------------------------------------------------------------
// Evaluation. One axis of a Hermite spline: for x, the cell and the weights w[d][slot] of
// its four data (slot 0 value at the left knot, 1 value at the right knot, 2 slope at the
// left, 3 slope at the right) for derivative orders d = 0..3, HYLC's extrapolation outside.

struct AxisBasis {
  int cell = 0;
  double w[4][4] = {};
};

AxisBasis axis_basis(const std::vector<double>& t, double x, int ext) {
  AxisBasis b;
  const int n = int(t.size());
  const int i = int(std::upper_bound(t.begin(), t.end(), x) - t.begin());  // first knot > x
  if (i == 0 || i == n) {  // outside: tangent extension at the nearest end (ext 1: constant, 2: zero)
    const bool left = i == 0;
    b.cell = left ? 0 : n - 2;
    const int vs = left ? 0 : 1, ss = left ? 2 : 3;
    const double dx = x - t[left ? 0 : n - 1];
    if (ext <= 1) b.w[0][vs] = 1;
    if (ext == 0) {
      b.w[0][ss] = dx;
      b.w[1][ss] = 1;
    }
    return b;
  }
  b.cell = i - 1;
  const double h = t[i] - t[i - 1], u = (x - t[i - 1]) / h, u2 = u * u, u3 = u2 * u;
  const double ih = 1 / h;
  // Value: h00, h01, h h10, h h11; each derivative in x divides by h.
  b.w[0][0] = 2 * u3 - 3 * u2 + 1;
  b.w[0][1] = -2 * u3 + 3 * u2;
  b.w[0][2] = h * (u3 - 2 * u2 + u);
  b.w[0][3] = h * (u3 - u2);
  b.w[1][0] = (6 * u2 - 6 * u) * ih;
  b.w[1][1] = (-6 * u2 + 6 * u) * ih;
  b.w[1][2] = 3 * u2 - 4 * u + 1;
  b.w[1][3] = 3 * u2 - 2 * u;
  b.w[2][0] = (12 * u - 6) * ih * ih;
  b.w[2][1] = (-12 * u + 6) * ih * ih;
  b.w[2][2] = (6 * u - 4) * ih;
  b.w[2][3] = (6 * u - 2) * ih;
  b.w[3][0] = 12 * ih * ih * ih;
  b.w[3][1] = -12 * ih * ih * ih;
  b.w[3][2] = 6 * ih * ih;
  b.w[3][3] = 6 * ih * ih;
  return b;
}

// d^k f / dS^k, k = 0..order, in scaled units.
void spline1d_jet(const HylcSpline1D& s, double x, int order, double* out) {
  const AxisBasis b = axis_basis(s.t, x, s.ext);
  const int c = b.cell;
  const double data[4] = {s.p[c], s.p[c + 1], s.m[c], s.m[c + 1]};
  for (int d = 0; d <= order; ++d) {
    double v = 0;
    for (int k = 0; k < 4; ++k) v += b.w[d][k] * data[k];
    out[d] = v;
  }
}

// The jet of a 2D spline (layout of core/jet_layout.hpp, d = 2, x = u, y = v), scaled units.
void spline2d_jet(const HylcSpline2D& s, double x, double y, int order, double* out) {
  const AxisBasis bu = axis_basis(s.tu, x, s.ext), bv = axis_basis(s.tv, y, s.ext);
  const int nu = int(s.tu.size()), cu = bu.cell, cv = bv.cell;
  // D[a][b]: a over u-slots, b over v-slots.
  double D[4][4];
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      const int j = cu + (a == 1 || a == 3), i = cv + (b == 1 || b == 3);
      const bool su = a >= 2, sv = b >= 2;
      const std::vector<double>& arr = su ? (sv ? s.muv : s.mu) : (sv ? s.mv : s.p);
      D[a][b] = arr[size_t(i) * nu + j];
    }
  auto partial = [&](int du, int dv) {
    double v = 0;
    for (int a = 0; a < 4; ++a) {
      if (bu.w[du][a] == 0) continue;
      double r = 0;
      for (int b = 0; b < 4; ++b) r += bv.w[dv][b] * D[a][b];
      v += bu.w[du][a] * r;
    }
    return v;
  };
  out[0] = partial(0, 0);
  if (order < 1) return;
  out[1] = partial(1, 0);
  out[2] = partial(0, 1);
  if (order < 2) return;
  out[3] = partial(2, 0);
  out[4] = partial(1, 1);
  out[5] = partial(0, 2);
  if (order < 3) return;
  out[6] = partial(3, 0);
  out[7] = partial(2, 1);
  out[8] = partial(1, 2);
  out[9] = partial(0, 3);
}

double min_spacing(const std::vector<double>& t) {
  double h = t[1] - t[0];
  for (size_t i = 2; i < t.size(); ++i) h = std::min(h, t[i] - t[i - 1]);
  return h;
}

// Our strain index of HYLC's k (4 -> 5).
int strain_of(int k) { return k == 4 ? 5 : k; }

}  // namespace

HylcMaterial read_hylc_material(const std::string& path) {
  const json j = io::read_json_file(path);
  const Reader r{{path}};
  if (!j.is_object()) r.fail("", "the file must hold a JSON object");
  HylcMaterial m;
  m.density = r.number(r.need(j, "density", ""), "density");
  if (m.density < 0) r.fail("density", "must be >= 0 (kg/m^2)");
  const std::vector<double> sc = r.numbers(r.need(j, "strain scale", ""), "strain scale");
  if (sc.size() != 5) r.fail("strain scale", "must hold 5 numbers (s_x, s_a, s_y, x-bending, y-bending)");
  for (int k = 0; k < 5; ++k) {
    if (!(sc[k] > 0)) r.fail("strain scale", "entries must be positive");
    m.scale[k] = sc[k];
  }
  if (j.contains("strain shift")) {
    const std::vector<double> sh = r.numbers(j["strain shift"], "strain shift");
    if (sh != std::vector<double>{1, 0, 1, 0, 0})
      r.fail("strain shift", "only [1, 0, 1, 0, 0] (s_x = |F e1| - 1, s_y = |F e2| - 1) is supported");
  }
  const json& co = r.need(j, "coeffs", "");
  m.c0 = r.number(r.need(co, "const", "coeffs"), "coeffs.const");
  const json& j1 = r.need(co, "1D", "coeffs");
  if (!j1.is_array()) r.fail("coeffs.1D", "must be an array");
  std::array<bool, 5> seen1{};
  for (size_t n = 0; n < j1.size(); ++n) {
    const std::string key = "coeffs.1D[" + std::to_string(n) + "]";
    const json& e = j1[n];
    HylcSpline1D s;
    s.k = r.index(r.need(e, "k", key), key + ".k", 0, 4);
    if (seen1[s.k]) r.fail(key + ".k", "a second 1D spline for k = " + std::to_string(s.k));
    seen1[s.k] = true;
    s.t = r.knots(r.need(e, "t", key), key + ".t");
    s.p = r.numbers(r.need(e, "p", key), key + ".p");
    s.m = r.numbers(r.need(e, "m", key), key + ".m");
    r.sized(s.p, s.t.size(), key + ".p");
    r.sized(s.m, s.t.size(), key + ".m");
    s.ext = r.ext(e, key);
    m.d1.push_back(std::move(s));
  }
  if (co.contains("2D")) {
    const json& j2 = co["2D"];
    if (!j2.is_array()) r.fail("coeffs.2D", "must be an array");
    std::vector<std::pair<int, int>> seen;
    for (size_t n = 0; n < j2.size(); ++n) {
      const std::string key = "coeffs.2D[" + std::to_string(n) + "]";
      const json& e = j2[n];
      HylcSpline2D s;
      s.k0 = r.index(r.need(e, "k0", key), key + ".k0", 0, 2);
      s.k1 = r.index(r.need(e, "k1", key), key + ".k1", 1, 4);
      if (s.k1 <= s.k0) r.fail(key + ".k1", "must be greater than k0");
      if (std::find(seen.begin(), seen.end(), std::make_pair(s.k0, s.k1)) != seen.end())
        r.fail(key, "a second 2D spline for (" + std::to_string(s.k0) + ", " + std::to_string(s.k1) + ")");
      seen.emplace_back(s.k0, s.k1);
      s.tu = r.knots(r.need(e, "tu", key), key + ".tu");
      s.tv = r.knots(r.need(e, "tv", key), key + ".tv");
      const size_t N = s.tu.size() * s.tv.size();
      s.p = r.numbers(r.need(e, "p", key), key + ".p");
      s.mu = r.numbers(r.need(e, "mu", key), key + ".mu");
      s.mv = r.numbers(r.need(e, "mv", key), key + ".mv");
      s.muv = e.contains("muv") ? r.numbers(e["muv"], key + ".muv") : std::vector<double>(N, 0.0);
      r.sized(s.p, N, key + ".p");
      r.sized(s.mu, N, key + ".mu");
      r.sized(s.mv, N, key + ".mv");
      r.sized(s.muv, N, key + ".muv");
      s.ext = r.ext(e, key);
      m.d2.push_back(std::move(s));
    }
  }
  return m;
}

void write_hylc_material(const std::string& path, const HylcMaterial& m) {
  json j;
  j["density"] = m.density;
  j["strain scale"] = std::vector<double>(m.scale.begin(), m.scale.end());
  j["strain shift"] = {1, 0, 1, 0, 0};
  json co;
  co["const"] = m.c0;
  co["1D"] = json::array();
  for (const HylcSpline1D& s : m.d1) co["1D"].push_back({{"k", s.k}, {"t", s.t}, {"p", s.p}, {"m", s.m}});
  co["2D"] = json::array();
  for (const HylcSpline2D& s : m.d2)
    co["2D"].push_back({{"k0", s.k0}, {"k1", s.k1}, {"tu", s.tu}, {"tv", s.tv}, {"p", s.p}, {"mu", s.mu}, {"mv", s.mv}, {"muv", s.muv}});
  j["coeffs"] = co;
  AtomicOutput out(path);
  {
    std::ofstream f(out.temp_path());
    if (!f) throw std::invalid_argument(path + ": cannot write");
    // nlohmann writes doubles round-trip exactly (shortest representation that reads back).
    f << j.dump(1) << "\n";
    if (!f) throw std::invalid_argument(path + ": write failed");
  }
  out.commit();
}

MaterialEval eval_hylc_material(const HylcMaterial& m, const Strain6& s) {
  MaterialEval out;
  out.psi = m.c0;
  for (const HylcSpline1D& sp : m.d1) {
    const double c = m.scale[sp.k];
    if (sp.k < 3) {
      double j[4];
      spline1d_jet(sp, s[sp.k] / c, 2, j);
      out.psi += j[0];
      out.grad[sp.k] += j[1] / c;
      out.hess(sp.k, sp.k) += j[2] / (c * c);
      continue;
    }
    // Bending: g(l) = f(l / c) in physical curvature.
    auto jet = [&sp, c](double, double l, int order, double* o) {
      spline1d_jet(sp, l / c, order, o);
      double f = 1;
      for (int d = 1; d <= order; ++d) o[d] *= (f /= c);
    };
    const BendingEval e = eval_bending_general(jet, false, 1e-2 * c * min_spacing(sp.t), sp.k == 3 ? 3 : 5, 0.0, s[3], s[4], s[5]);
    out.psi += e.value;
    for (int a = 1; a < 4; ++a) {
      out.grad[2 + a] += e.grad[a];
      for (int b = 1; b < 4; ++b) out.hess(2 + a, 2 + b) += e.hess(a, b);
    }
  }
  for (const HylcSpline2D& sp : m.d2) {
    const double cu = m.scale[sp.k0], cv = m.scale[sp.k1];
    const int iu = sp.k0;
    if (sp.k1 < 3) {
      const int iv = sp.k1;
      double j[10];
      spline2d_jet(sp, s[iu] / cu, s[iv] / cv, 2, j);
      out.psi += j[0];
      out.grad[iu] += j[1] / cu;
      out.grad[iv] += j[2] / cv;
      out.hess(iu, iu) += j[3] / (cu * cu);
      out.hess(iu, iv) += j[4] / (cu * cv);
      out.hess(iv, iu) += j[4] / (cu * cv);
      out.hess(iv, iv) += j[5] / (cv * cv);
      continue;
    }
    auto jet = [&sp, cu, cv](double p, double l, int order, double* o) {
      spline2d_jet(sp, p / cu, l / cv, order, o);
      // Channel (i x's, j y's) scales by 1 / (cu^i cv^j).
      static const int nx[10] = {0, 1, 0, 2, 1, 0, 3, 2, 1, 0}, ny[10] = {0, 0, 1, 0, 1, 2, 0, 1, 2, 3};
      for (int c = 1; c < jet_channels(2, order); ++c) o[c] /= std::pow(cu, nx[c]) * std::pow(cv, ny[c]);
    };
    const BendingEval e = eval_bending_general(jet, true, 1e-2 * cv * min_spacing(sp.tv), sp.k1 == 3 ? 3 : 5, s[iu], s[3], s[4], s[5]);
    out.psi += e.value;
    const int map[4] = {iu, 3, 4, 5};
    for (int a = 0; a < 4; ++a) {
      out.grad[map[a]] += e.grad[a];
      for (int b = 0; b < 4; ++b) out.hess(map[a], map[b]) += e.hess(a, b);
    }
  }
  (void)strain_of;
  return out;
}

HylcMaterial hylc_from_baked(const BakedModel& baked, double areal_density, double margin) {
  HylcMaterial m;
  m.density = areal_density;
  m.c0 = baked.psi0;
  // Bending scales: the largest |bound| of the bending boxes (cosmetic: knots near [-1, 1]).
  for (const BakedTable& t : baked.tables)
    for (size_t a = 0; a < t.term.indices.size(); ++a) {
      const int i = t.term.indices[a];
      if (i == 3 || i == 5) {
        const double b = std::max(std::abs(t.lower[a]), std::abs(t.upper[a]));
        double& sc = m.scale[i == 3 ? 3 : 4];
        sc = sc == 1 ? b : std::max(sc, b);
      }
    }
  auto hk = [](int i) { return i == 5 ? 4 : i; };
  // The knots of one axis: the box's, plus two beyond each end at margin/2 and margin widths.
  auto axis = [margin](double lo, double hi, int n) {
    std::vector<double> x;
    const double w = hi - lo;
    if (margin > 0) {
      x.push_back(lo - margin * w);
      x.push_back(lo - 0.5 * margin * w);
    }
    for (int k = 0; k < n; ++k) x.push_back(k == n - 1 ? hi : lo + w * k / (n - 1));
    if (margin > 0) {
      x.push_back(hi + 0.5 * margin * w);
      x.push_back(hi + margin * w);
    }
    return x;
  };
  for (const BakedTable& t : baked.tables) {
    const BakedTerm bt = make_baked_term(t);
    if (t.dim() == 1) {
      const int i = t.term.indices[0];
      const double c = m.scale[hk(i)];
      HylcSpline1D s;
      s.k = hk(i);
      for (double x : axis(t.lower[0], t.upper[0], t.knots[0])) {
        const BakedJet1 j = eval_baked_1d(bt, x);
        s.t.push_back(x / c);
        s.p.push_back(j.f);
        s.m.push_back(j.df * c);
      }
      m.d1.push_back(std::move(s));
    } else {
      const int i0 = t.term.indices[0], i1 = t.term.indices[1];
      const double cu = m.scale[hk(i0)], cv = m.scale[hk(i1)];
      HylcSpline2D s;
      s.k0 = hk(i0);
      s.k1 = hk(i1);
      const std::vector<double> xu = axis(t.lower[0], t.upper[0], t.knots[0]), xv = axis(t.lower[1], t.upper[1], t.knots[1]);
      for (double u : xu) s.tu.push_back(u / cu);
      for (double v : xv) s.tv.push_back(v / cv);
      for (double v : xv)
        for (double u : xu) {
          double j[10];
          const double pt[2] = {u, v};
          eval_baked_jet(bt, pt, 2, j);
          s.p.push_back(j[0]);
          s.mu.push_back(j[1] * cu);
          s.mv.push_back(j[2] * cv);
          s.muv.push_back(j[4] * cu * cv);
        }
      m.d2.push_back(std::move(s));
    }
  }
  return m;
}

}  // namespace yarnhom
