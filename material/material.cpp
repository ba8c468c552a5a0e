#include "material/material.hpp"

#include <cmath>
#include <stdexcept>

#include "core/jet_layout.hpp"

namespace yarnhom {

namespace {

// S = (h(m+r) + h(m-r))/2 and A = (h(m+r) - h(m-r))/(2r) with their derivatives in m and
// q = rho = r^2 (suffix q), up to second order.
struct EvenOdd {
  double S, Sm, Smm, Sq, Smq, Sqq, A, Am, Amm, Aq, Amq, Aqq;
};

// Closed forms from h, h', h'' at u = m + r and v = m - r (r > 0). With F_q = F_r / (2r) and
// F_qq = (F_rr - F_r / r) / (4 r^2).
EvenOdd exact_parts(const double hu[3], const double hv[3], double r) {
  const double ir = 1.0 / r, ir2 = ir * ir;
  EvenOdd e;
  e.S = 0.5 * (hu[0] + hv[0]);
  e.Sm = 0.5 * (hu[1] + hv[1]);
  e.Smm = 0.5 * (hu[2] + hv[2]);
  const double Sr = 0.5 * (hu[1] - hv[1]), Srr = 0.5 * (hu[2] + hv[2]), Smr = 0.5 * (hu[2] - hv[2]);
  e.Sq = 0.5 * Sr * ir;
  e.Smq = 0.5 * Smr * ir;
  e.Sqq = 0.25 * (Srr - Sr * ir) * ir2;
  const double N = hu[0] - hv[0], Nr = hu[1] + hv[1], Nrr = hu[2] - hv[2];
  e.A = 0.5 * N * ir;
  e.Am = 0.5 * (hu[1] - hv[1]) * ir;
  e.Amm = 0.5 * (hu[2] - hv[2]) * ir;
  const double Ar = 0.5 * Nr * ir - 0.5 * N * ir2;
  const double Arr = 0.5 * Nrr * ir - Nr * ir2 + N * ir2 * ir;
  const double Amr = 0.5 * (hu[2] + hv[2]) * ir - 0.5 * (hu[1] - hv[1]) * ir2;
  e.Aq = 0.5 * Ar * ir;
  e.Amq = 0.5 * Amr * ir;
  e.Aqq = 0.25 * (Arr - Ar * ir) * ir2;
  return e;
}

// Taylor series in q from the jet h0..h3 of h at m, truncated after the cubic terms of h:
// S = h + h'' q/2 + O(h'''' q^2), A = h' + h''' q/6 + O(h''''' q^2). Exact for a cubic h.
EvenOdd series_parts(const double h[4], double q) {
  EvenOdd e;
  e.S = h[0] + 0.5 * h[2] * q;
  e.Sm = h[1] + 0.5 * h[3] * q;
  e.Smm = h[2];
  e.Sq = 0.5 * h[2];
  e.Smq = 0.5 * h[3];
  e.Sqq = 0.0;
  e.A = h[1] + h[3] * q / 6.0;
  e.Am = h[2];
  e.Amm = h[3];
  e.Aq = h[3] / 6.0;
  e.Amq = 0.0;
  e.Aqq = 0.0;
  return e;
}

// T = S + d A, the mixing's value, out of line: the value-alone path (bending3_value below)
// gets it by the same instructions (a contraction of d A + S into one fused multiply-add is
// the compiler's choice per call site).
[[gnu::noinline]] double mixed_value(double S, double d, double A) { return S + d * A; }

// Value, gradient and Hessian of B_3 in (p, II_x, II_a, II_y) for any curvature function:
// jet(l, order, out) writes the jet of the term at curvature l (and the fixed p), in the
// layout of core/jet_layout.hpp; tau is the umbilic series' switch radius.
template <class Jet>
BendingEval bending3_of(const Jet& jet, bool two, double tau, double p, double a, double b, double c) {
  const double m = 0.5 * (a + c), d = 0.5 * (a - c);
  const double r = std::hypot(d, b), q = r * r;
  EvenOdd G, P{}, PP{};  // parts of g, g_p, g_pp as functions of the curvature
  if (r >= tau) {
    double ju[10], jv[10];
    jet(m + r, 2, ju);
    jet(m - r, 2, jv);
    if (!two) {
      G = exact_parts(ju, jv, r);
    } else {
      // Channels (d = 2, x = p, y = curvature): 0 f, 1 f_p, 2 f_l, 3 f_pp, 4 f_pl, 5 f_ll.
      const double gu[3] = {ju[0], ju[2], ju[5]}, gv[3] = {jv[0], jv[2], jv[5]};
      const double pu[3] = {ju[1], ju[4], 0}, pv[3] = {jv[1], jv[4], 0};
      const double ppu[3] = {ju[3], 0, 0}, ppv[3] = {jv[3], 0, 0};
      G = exact_parts(gu, gv, r);
      P = exact_parts(pu, pv, r);    // only S, Sm, Sq, A, Am, Aq are used
      PP = exact_parts(ppu, ppv, r);  // only S, A are used
    }
  } else {
    double jm[10];
    jet(m, 3, jm);
    if (!two) {
      G = series_parts(jm, q);
    } else {
      // 6 f_ppp, 7 f_ppl, 8 f_pll, 9 f_lll. d^4 f/dp dl^3 is beyond the jet; it enters only
      // through terms of order q, below 1e-4 of the knot spacing squared here.
      const double g[4] = {jm[0], jm[2], jm[5], jm[9]};
      const double gp[4] = {jm[1], jm[4], jm[8], 0};
      const double gpp[4] = {jm[3], jm[7], 0, 0};
      G = series_parts(g, q);
      P = series_parts(gp, q);
      PP = series_parts(gpp, q);
    }
  }
  // T(p, m, d, b) = S + d A with S, A functions of (p, m, q = d^2 + b^2).
  const double Q = G.Sq + d * G.Aq, R = G.Sqq + d * G.Aqq;
  const double T = mixed_value(G.S, d, G.A);
  const double Tp = P.S + d * P.A, Tm = G.Sm + d * G.Am, Td = 2 * d * Q + G.A, Tb = 2 * b * Q;
  const double Tpp = PP.S + d * PP.A, Tpm = P.Sm + d * P.Am;
  const double Qp = P.Sq + d * P.Aq, Tpd = 2 * d * Qp + P.A, Tpb = 2 * b * Qp;
  const double Qm = G.Smq + d * G.Amq;
  const double Tmm = G.Smm + d * G.Amm, Tmd = 2 * d * Qm + G.Am, Tmb = 2 * b * Qm;
  const double Tdd = 2 * Q + 4 * d * d * R + 4 * d * G.Aq;
  const double Tdb = 4 * d * b * R + 2 * b * G.Aq;
  const double Tbb = 2 * Q + 4 * b * b * R;
  // (m, d) -> (II_x, II_y): d/dII_x = (d/dm + d/dd)/2, d/dII_y = (d/dm - d/dd)/2.
  BendingEval e;
  e.value = T;
  e.grad << Tp, 0.5 * (Tm + Td), Tb, 0.5 * (Tm - Td);
  Eigen::Matrix4d& H = e.hess;
  H(0, 0) = Tpp;
  H(0, 1) = 0.5 * (Tpm + Tpd);
  H(0, 2) = Tpb;
  H(0, 3) = 0.5 * (Tpm - Tpd);
  H(1, 1) = 0.25 * (Tmm + 2 * Tmd + Tdd);
  H(1, 2) = 0.5 * (Tmb + Tdb);
  H(1, 3) = 0.25 * (Tmm - Tdd);
  H(2, 2) = Tbb;
  H(2, 3) = 0.5 * (Tmb - Tdb);
  H(3, 3) = 0.25 * (Tmm - 2 * Tmd + Tdd);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < i; ++j) H(i, j) = H(j, i);
  if (!two) {  // no p
    e.grad[0] = 0;
    H.row(0).setZero();
    H.col(0).setZero();
  }
  return e;
}

// The baked table's instance: the fast value-gradient-Hessian paths up to order 2.
BendingEval bending3(const BakedTerm& t, double p, double a, double b, double c) {
  const bool two = t.dim == 2;
  const int lam = two ? 1 : 0;  // the curvature axis of the table
  const double tau = 1e-2 / t.inv_h[lam];
  auto jet = [&](double l, int order, double* out) {

    if (order <= 2) {  // the fast value-gradient-Hessian paths
      if (two) {
        const BakedJet2 r = eval_baked_2d(t, {p, l});
        out[0] = r.f;
        out[1] = r.g[0];
        out[2] = r.g[1];
        out[3] = r.H(0, 0);
        out[4] = r.H(0, 1);
        out[5] = r.H(1, 1);
      } else {
        const BakedJet1 r = eval_baked_1d(t, l);
        out[0] = r.f;
        out[1] = r.df;
        out[2] = r.d2f;
      }
    } else if (two) {
      const double s[2] = {p, l};
      eval_baked_jet(t, s, order, out);
    } else {
      eval_baked_jet(t, &l, order, out);
    }
  };
  return bending3_of(jet, two, tau, p, a, b, c);
}

}  // namespace

namespace {

// An evaluation made at (p, II_y, II_a, II_x) expressed in (p, II_x, II_a, II_y): swaps the
// derivatives in II_x and II_y (a permutation P of the gradient, P H P of the Hessian).
BendingEval swap_curvature_axes(BendingEval e) {
  std::swap(e.grad[1], e.grad[3]);
  Eigen::Matrix4d P = Eigen::Matrix4d::Identity();
  P(1, 1) = P(3, 3) = 0;
  P(1, 3) = P(3, 1) = 1;
  e.hess = P * e.hess * P;
  return e;
}

}  // namespace

namespace {

// bending3(t, p, a, b, c).value: away from the umbilic T = S + d A from the values at m +- r
// (exact_parts' S and A), else the series of the full path.
double bending3_value(const BakedTerm& t, double p, double a, double b, double c) {
  const bool two = t.dim == 2;
  const double tau = 1e-2 / t.inv_h[two ? 1 : 0];
  const double m = 0.5 * (a + c), d = 0.5 * (a - c);
  const double r = std::hypot(d, b);
  if (!(r >= tau)) return bending3(t, p, a, b, c).value;
  const double fu = two ? eval_baked_2d_value(t, {p, m + r}) : eval_baked_1d_value(t, m + r);
  const double fv = two ? eval_baked_2d_value(t, {p, m - r}) : eval_baked_1d_value(t, m - r);
  const double ir = 1.0 / r;
  const double N = fu - fv;
  return mixed_value(0.5 * (fu + fv), d, 0.5 * N * ir);  // exact_parts' S and A
}

}  // namespace

double eval_bending_value(const BakedTerm& t, int which, double p, double IIx, double IIa, double IIy) {
  if (which == 3) return bending3_value(t, p, IIx, IIa, IIy);
  if (which != 5) throw std::invalid_argument("eval_bending_value: which must be 3 or 5");
  return bending3_value(t, p, IIy, IIa, IIx);
}

BendingEval eval_bending(const BakedTerm& t, int which, double p, double IIx, double IIa, double IIy) {
  if (which == 3) return bending3(t, p, IIx, IIa, IIy);
  if (which != 5) throw std::invalid_argument("eval_bending: which must be 3 or 5");
  // B_5[g](II_x, II_a, II_y) = B_3[g](II_y, II_a, II_x): swapping the diagonal entries of K
  // swaps c2 and 1 - c2.
  return swap_curvature_axes(bending3(t, p, IIy, IIa, IIx));
}

BendingEval eval_bending_general(const CurvatureJet& jet, bool two_d, double tau, int which, double p, double IIx,
                                 double IIa, double IIy) {
  if (which != 3 && which != 5) throw std::invalid_argument("eval_bending_general: which must be 3 or 5");
  auto j = [&](double l, int order, double* out) { jet(p, l, order, out); };
  if (which == 3) return bending3_of(j, two_d, tau, p, IIx, IIa, IIy);
  return swap_curvature_axes(bending3_of(j, two_d, tau, p, IIy, IIa, IIx));  // B_5 as in eval_bending
}

BakedMaterial make_baked_material(const BakedModel& m, const std::string& file, std::string* missing) {
  BakedMaterial mat;
  mat.psi0 = m.psi0;
  mat.areal_density = m.areal_density;
  const auto& terms = all_terms();
  for (size_t k = 0; k < terms.size(); ++k) {
    const BakedTable* t = m.find(terms[k].name);
    if (t) {
      mat.terms[k] = make_baked_term(*t, file);
    } else if (missing) {
      *missing += (missing->empty() ? "" : " ") + terms[k].name;
    }
  }
  return mat;
}

namespace {

// Calls f(table, indices, bend, p) for every term the material has, in the terms' order: bend
// is 3 or 5 for a bending term (p its in-plane argument's index, or -1 for a 1D term), -1 for
// an in-plane term (whose arguments are its indices).
template <class F>
void for_each_baked_term(const BakedMaterial& mat, F&& f) {
  const auto& terms = all_terms();
  for (size_t k = 0; k < terms.size(); ++k) {
    if (!mat.terms[k]) continue;
    const std::vector<int>& idx = terms[k].indices;
    const int bend = idx.back() == 3 || idx.back() == 5 ? idx.back() : -1;
    f(*mat.terms[k], idx, bend, bend >= 0 && idx.size() == 2 ? idx[0] : -1);
  }
}

}  // namespace

double eval_material_value(const BakedMaterial& mat, const Strain6& s) {
  double psi = mat.psi0;
  for_each_baked_term(mat, [&](const BakedTerm& t, const std::vector<int>& idx, int bend, int pi) {
    if (bend < 0)
      psi += idx.size() == 1 ? eval_baked_1d_value(t, s[idx[0]]) : eval_baked_2d_value(t, {s[idx[0]], s[idx[1]]});
    else
      psi += eval_bending_value(t, bend, pi >= 0 ? s[pi] : 0.0, s[3], s[4], s[5]);
  });
  return psi;
}

MaterialEval eval_material(const BakedMaterial& mat, const Strain6& s) {
  MaterialEval out;
  out.psi = mat.psi0;
  for_each_baked_term(mat, [&](const BakedTerm& t, const std::vector<int>& idx, int bend, int pi) {
    if (bend < 0) {  // in-plane: the table's own arguments
      if (idx.size() == 1) {
        const BakedJet1 j = eval_baked_1d(t, s[idx[0]]);
        out.psi += j.f;
        out.grad[idx[0]] += j.df;
        out.hess(idx[0], idx[0]) += j.d2f;
      } else {
        const BakedJet2 j = eval_baked_2d(t, {s[idx[0]], s[idx[1]]});
        out.psi += j.f;
        for (int a = 0; a < 2; ++a) {
          out.grad[idx[a]] += j.g[a];
          for (int b = 0; b < 2; ++b) out.hess(idx[a], idx[b]) += j.H(a, b);
        }
      }
      return;
    }
    const BendingEval e = eval_bending(t, bend, pi >= 0 ? s[pi] : 0.0, s[3], s[4], s[5]);
    const int map[4] = {pi, 3, 4, 5};
    out.psi += e.value;
    for (int a = 0; a < 4; ++a) {
      if (map[a] < 0) continue;
      out.grad[map[a]] += e.grad[a];
      for (int b = 0; b < 4; ++b)
        if (map[b] >= 0) out.hess(map[a], map[b]) += e.hess(a, b);
    }
  });
  return out;
}

}  // namespace yarnhom
