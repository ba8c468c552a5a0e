#include "cpu/losses.hpp"

#include <cmath>

namespace yarnhom::cpu {

template <class T>
LossSums<T> data_losses(int d, int B, int order, const T* jet, const T* y, const T* g, const T* wt,
                        const LossWeights& w, bool exact_c, T scale, T* djet) {
  LossSums<T> sum;
  const T wz = T(w.z) * scale, wf = T(w.f) * scale, wc = T(w.c) * scale, wx = T(w.x) * scale;
  auto ch = [&](int c, int p) { return jet[size_t(c) * B + p]; };
  auto adj = [&](int c, int p) -> T& { return djet[size_t(c) * B + p]; };
  for (int p = 0; p < B; ++p) {
    const T k = wt ? wt[p] : T(1);  // the point's weight on its L_Z and L_F residuals
    if (w.z != 0) {
      const T r = ch(0, p) - y[p];
      sum.z += k * r * r;
      if (djet) adj(0, p) += wz * T(2) * k * r;
    }
    if (w.f != 0) {
      for (int i = 0; i < d; ++i) {
        const T r = ch(1 + i, p) - g[p * d + i];
        sum.f += k * r * r;
        if (djet) adj(1 + i, p) += wf * T(2) * k * r;
      }
    }
    if (w.c != 0 && exact_c && order >= 3) {
      for (int t = 0; t < jet_num_triples(d); ++t) {
        const int c = jet_first(d, 3) + t;
        const T v = ch(c, p);
        sum.c += std::abs(v);
        if (djet) adj(c, p) += wc * T((v > 0) - (v < 0));  // d|v|/dv = sign(v), 0 at 0
      }
    }
    if (w.x != 0 && order >= 2) {
      T lam, da = 1, db = 0, dc = 0;
      const int c0 = jet_first(d, 2);
      if (d == 1)
        lam = ch(c0, p);
      else
        lam = min_eigenvalue_2x2(ch(c0, p), ch(c0 + 1, p), ch(c0 + 2, p), &da, &db, &dc);
      if (lam < 0) {
        sum.x += lam * lam;
        if (djet) {
          const T gl = wx * T(2) * lam;  // d relu(-lam)^2 / d lam = 2 lam for lam < 0
          adj(c0, p) += gl * da;
          if (d == 2) {
            adj(c0 + 1, p) += gl * db;
            adj(c0 + 2, p) += gl * dc;
          }
        }
      }
    }
  }
  return sum;
}

template <class T>
T strain_concentration_loss(int d, int K, int order, const T* jet, const T* normals,
                            T weight_scale, T* djet) {
  T sum = 0;
  for (int p = 0; p < K; ++p) {
    T dot = 0;
    for (int i = 0; i < d; ++i) dot += jet[size_t(1 + i) * K + p] * normals[p * d + i];
    if (dot < 0) {  // relu(-dot)^2, derivative -2 relu(-dot) = 2 dot
      sum += dot * dot;
      if (djet)
        for (int i = 0; i < d; ++i) djet[size_t(1 + i) * K + p] += weight_scale * T(2) * dot * normals[p * d + i];
    }
  }
  return sum;
}

template LossSums<float> data_losses<float>(int, int, int, const float*, const float*, const float*,
                                            const float*, const LossWeights&, bool, float, float*);
template LossSums<double> data_losses<double>(int, int, int, const double*, const double*, const double*,
                                              const double*, const LossWeights&, bool, double,
                                              double*);
template float strain_concentration_loss<float>(int, int, int, const float*, const float*, float,
                                                float*);
template double strain_concentration_loss<double>(int, int, int, const double*, const double*,
                                                  double, double*);

}  // namespace yarnhom::cpu
