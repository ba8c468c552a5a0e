#include "sim/hessian_pattern.hpp"

#include <algorithm>

namespace yarnhom::sim {

namespace {

int element_vertex(const Mesh& m, int t, int a) { return a < 3 ? m.tris(t, a) : m.flaps(t, a - 3); }

// Calls fn(t, a, b, fa, fb) for every pair (a, b) of an element's six vertices (the triangle
// and its flaps) that are both free, with fa >= fb their free indices (the lower triangle).
template <class Fn>
void for_each_lower_pair(const Mesh& mesh, const DofMap& dofs, Fn&& fn) {
  for (int t = 0; t < mesh.num_triangles(); ++t)
    for (int a = 0; a < 6; ++a)
      for (int b = 0; b < 6; ++b) {
        const int va = element_vertex(mesh, t, a), vb = element_vertex(mesh, t, b);
        if (va < 0 || vb < 0) continue;
        const int fa = dofs.free_index[va], fb = dofs.free_index[vb];
        if (fa < 0 || fb < 0 || fa < fb) continue;
        fn(t, a, b, fa, fb);
      }
}

}  // namespace

HessianPattern make_hessian_pattern(const Mesh& mesh, const DofMap& dofs) {
  const int F = dofs.num_free(), m = mesh.num_triangles();
  // Vertex-level adjacency (lower: row vertex >= column vertex), then expanded to 3x3 blocks.
  std::vector<std::vector<int>> rows_of(F);
  for (int f = 0; f < F; ++f) rows_of[f].push_back(f);
  for_each_lower_pair(mesh, dofs, [&](int, int, int, int fa, int fb) { rows_of[fb].push_back(fa); });
  for (auto& r : rows_of) {
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
  }
  // Column-major lower storage: column 3fb + c holds, for each row vertex fa in rows_of[fb],
  // rows 3fa + (c if fa == fb else 0) .. 3fa + 2.
  HessianPattern p;
  const int N = 3 * F;
  std::vector<int> outer(N + 1, 0);
  for (int fb = 0; fb < F; ++fb)
    for (int c = 0; c < 3; ++c) outer[3 * fb + c + 1] = outer[3 * fb + c] + 3 * int(rows_of[fb].size()) - c;
  const int nnz = outer[N];
  std::vector<int> inner(nnz);
  // first[fb][k][c]: value index of the first stored row of block (rows_of[fb][k], fb) in
  // column component c.
  std::vector<std::vector<std::array<int, 3>>> first(F);
  for (int fb = 0; fb < F; ++fb) {
    first[fb].resize(rows_of[fb].size());
    for (int c = 0; c < 3; ++c) {
      int pos = outer[3 * fb + c];
      for (size_t k = 0; k < rows_of[fb].size(); ++k) {
        const int fa = rows_of[fb][k];
        const int r0 = fa == fb ? c : 0;
        first[fb][k][c] = pos;
        for (int r = r0; r < 3; ++r) inner[pos++] = 3 * fa + r;
      }
    }
  }
  p.matrix.resize(N, N);
  p.matrix.resizeNonZeros(nnz);
  std::copy(outer.begin(), outer.end(), p.matrix.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), p.matrix.innerIndexPtr());
  std::fill(p.matrix.valuePtr(), p.matrix.valuePtr() + nnz, 0.0);
  auto lookup = [&](int fa, int fb, int c) {
    const auto& r = rows_of[fb];
    const size_t k = std::lower_bound(r.begin(), r.end(), fa) - r.begin();
    return first[fb][k][c];
  };
  p.diag_slots.resize(size_t(F) * 3);
  for (int f = 0; f < F; ++f)
    for (int c = 0; c < 3; ++c) p.diag_slots[3 * f + c] = lookup(f, f, c);
  p.elem_slots.assign(size_t(m) * 108, -1);
  p.same_vertex.assign(m, 0);
  for_each_lower_pair(mesh, dofs, [&](int t, int a, int b, int fa, int fb) {
    for (int c = 0; c < 3; ++c) p.elem_slots[((size_t(t) * 6 + a) * 6 + b) * 3 + c] = lookup(fa, fb, c);
    if (fa == fb) p.same_vertex[t] |= 1ull << (6 * a + b);
  });
  return p;
}

void add_element_hessian(const HessianPattern& p, int t, const Eigen::Matrix<double, 18, 18>& H, double* values) {
  const int* s = &p.elem_slots[size_t(t) * 108];
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 6; ++b) {
      const int* sc = s + (a * 6 + b) * 3;
      if (sc[0] < 0) continue;
      // Slots holding the same vertex (a == b, or two flaps that coincide in a small mesh) add
      // to its diagonal block, lower part only; (a, b) and (b, a) then each add their own.
      const bool same = (p.same_vertex[t] >> (6 * a + b)) & 1;
      for (int c = 0; c < 3; ++c) {
        double* v = values + sc[c];
        for (int r = same ? c : 0; r < 3; ++r) *v++ += H(3 * a + r, 3 * b + c);
      }
    }
}

void add_vertex_hessian(const HessianPattern& p, int f, const Eigen::Matrix3d& H, double* values) {
  for (int c = 0; c < 3; ++c) {
    double* v = values + p.diag_slots[3 * f + c];
    for (int r = c; r < 3; ++r) *v++ += H(r, c);
  }
}

namespace {
constexpr Eigen::Index kParallelValues = 1 << 16;
}

void copy_pattern(const Eigen::SparseMatrix<double>& src, Eigen::SparseMatrix<double>& dst) {
  const Eigen::SparseMatrix<double> compressed = src.isCompressed() ? Eigen::SparseMatrix<double>() : src;
  const Eigen::SparseMatrix<double>& A = src.isCompressed() ? src : compressed;
  dst.resize(A.rows(), A.cols());
  const Eigen::Index nnz = A.nonZeros();
  dst.resizeNonZeros(nnz);
  std::copy(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1, dst.outerIndexPtr());
  const int* in = A.innerIndexPtr();
  int* out = dst.innerIndexPtr();
  double* v = dst.valuePtr();
#pragma omp parallel for schedule(static) if (nnz >= kParallelValues)
  for (Eigen::Index k = 0; k < nnz; ++k) out[k] = in[k], v[k] = 0.0;
}

void fill_values(Eigen::SparseMatrix<double>& A, double v) {
  double* p = A.valuePtr();
  const Eigen::Index nnz = A.nonZeros();
#pragma omp parallel for schedule(static) if (nnz >= kParallelValues)
  for (Eigen::Index k = 0; k < nnz; ++k) p[k] = v;
}

}  // namespace yarnhom::sim
