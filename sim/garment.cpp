#include "sim/garment.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <stdexcept>

namespace yarnhom::sim {

double seam_energy(const Problem& P, const std::vector<int>& free_index, const Eigen::VectorXd& x, double t,
                   Eigen::VectorXd* grad, std::vector<Eigen::Triplet<double>>* trip) {
  if (P.stitches.empty() || !(P.stitch_stiffness > 0)) return 0.0;
  const double k = P.stitch_stiffness;
  const double g = P.sew_time > 0 ? std::max(0.0, 1.0 - t / P.sew_time) : 0.0;
  double E = 0;
  for (const Stitch& s : P.stitches) {
    const Eigen::Vector3d r = x.segment<3>(3 * s.a) - x.segment<3>(3 * s.b) - g * s.offset0;
    E += 0.5 * k * r.squaredNorm();
    if (grad) {
      grad->segment<3>(3 * s.a) += k * r;
      grad->segment<3>(3 * s.b) -= k * r;
    }
    if (!trip) continue;
    const int fa = free_index.empty() ? s.a : free_index[s.a], fb = free_index.empty() ? s.b : free_index[s.b];
    // k [I -I; -I I], lower triangle over the free unknowns.
    for (int f : {fa, fb})
      if (f >= 0)
        for (int c = 0; c < 3; ++c) trip->emplace_back(3 * f + c, 3 * f + c, k);
    if (fa >= 0 && fb >= 0 && fa != fb) {
      const int hi = std::max(fa, fb), lo = std::min(fa, fb);
      for (int c = 0; c < 3; ++c) trip->emplace_back(3 * hi + c, 3 * lo + c, -k);
    }
  }
  return E;
}

std::vector<int> stitch_representatives(int n, const std::vector<Stitch>& stitches) {
  std::vector<int> rep(n);
  std::iota(rep.begin(), rep.end(), 0);
  std::function<int(int)> find = [&](int v) { return rep[v] == v ? v : rep[v] = find(rep[v]); };
  for (const Stitch& s : stitches) {
    const int a = find(s.a), b = find(s.b);
    if (a != b) rep[std::max(a, b)] = std::min(a, b);
  }
  for (int v = 0; v < n; ++v) rep[v] = find(v);
  return rep;
}

namespace {

// The pattern in panel coordinates (x across, z up from the hem), metres.
constexpr double kHalfTorso = 0.24, kSleeveEnd = 0.64, kHalfNeck = 0.08, kHeight = 0.64, kArmpit = 0.32;
constexpr double kHem = 0.86;      // hem height on the mannequin, m
constexpr double kPanelGap = 0.16; // panels start at y = +-0.16 m

bool inside_pattern(double x, double z) {
  return z > 0 && z < kHeight && (std::abs(x) < kHalfTorso || (z > kArmpit && std::abs(x) < kSleeveEnd));
}

// On a sewn edge: the sides and under the sleeves, the shoulders and the sleeves' tops.
bool on_seam(double x, double z, double tol) {
  const double ax = std::abs(x);
  const bool side = std::abs(ax - kHalfTorso) < tol && z <= kArmpit + tol;
  const bool under = std::abs(z - kArmpit) < tol && ax >= kHalfTorso - tol && ax <= kSleeveEnd + tol;
  const bool top = std::abs(z - kHeight) < tol && ax >= kHalfNeck - tol && ax <= kSleeveEnd + tol;
  return side || under || top;
}

}  // namespace

Scene tshirt_garment(int k) {
  if (k < 1 || k > 80) throw std::invalid_argument("tshirt: --resolution must be between 1 and 80 (grid spacing 8 cm / resolution)");
  const double h = 0.08 / k;
  const int nx = int(std::lround(2 * kSleeveEnd / h)), nz = int(std::lround(kHeight / h));
  auto gx = [&](int i) { return -kSleeveEnd + i * h; };
  auto gz = [&](int j) { return j * h; };
  // Cells of the pattern, then the vertices they use (one panel).
  std::vector<int> id((nx + 1) * (nz + 1), -1);
  std::vector<std::array<int, 2>> verts;
  std::vector<std::array<int, 2>> cells;
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i)
      if (inside_pattern(gx(i) + h / 2, gz(j) + h / 2)) cells.push_back({i, j});
  auto vid = [&](int i, int j) {
    int& v = id[j * (nx + 1) + i];
    if (v < 0) {
      v = int(verts.size());
      verts.push_back({i, j});
    }
    return v;
  };
  std::vector<std::array<int, 3>> tris;
  for (const auto& [i, j] : cells) {
    const int a = vid(i, j), b = vid(i + 1, j), c = vid(i + 1, j + 1), d = vid(i, j + 1);
    if ((i + j) % 2 == 0) tris.push_back({a, b, c}), tris.push_back({a, c, d});
    else tris.push_back({a, b, d}), tris.push_back({b, c, d});
  }
  const int n = int(verts.size()), m = int(tris.size());
  Scene s;
  s.name = "tshirt";
  s.mesh.rest.resize(2 * n, 2);
  s.mesh.x.resize(2 * n, 3);
  s.mesh.tris.resize(2 * m, 3);
  // Front (panel 0): rest (x + 0.6, z), at y = +gap, faces +y... Back (panel 1): mirrored rest
  // (1.9 - x, z) so that its triangles, counterclockwise in the rest plane, face -y.
  for (int p = 0; p < 2; ++p) {
    for (int v = 0; v < n; ++v) {
      const double x = gx(verts[v][0]), z = gz(verts[v][1]);
      s.mesh.rest.row(p * n + v) << (p == 0 ? x + kSleeveEnd : 3 * kSleeveEnd + 0.1 - x), z;
      s.mesh.x.row(p * n + v) << x, p == 0 ? kPanelGap : -kPanelGap, kHem + z;
    }
    for (int t = 0; t < m; ++t) {
      const auto& T = tris[t];
      if (p == 0) s.mesh.tris.row(t) << T[0], T[1], T[2];
      else s.mesh.tris.row(m + t) << n + T[0], n + T[2], n + T[1];
    }
  }
  finish_mesh(s.mesh, "tshirt");
  for (int v = 0; v < n; ++v) {
    const double x = gx(verts[v][0]), z = gz(verts[v][1]);
    if (on_seam(x, z, 1e-6)) s.stitches.push_back({v, n + v, Eigen::Vector3d::Zero()});
  }
  s.stitch_stiffness = 2000 * h;  // N/m per stitch: ~2 N per metre of seam per mm of gap
  s.sew_time = 0.5;
  s.gravity_delay = 0.5;
  return s;
}

std::vector<CapsuleObstacle> mannequin_capsules() {
  // Torso, neck and arms held out sideways (T pose).
  auto capsule = [](Eigen::Vector3d a, Eigen::Vector3d b, double r) {
    CapsuleObstacle c;
    c.a = a, c.b = b, c.radius = r, c.friction = 0.3;
    return c;
  };
  return {capsule({0, 0, 0.80}, {0, 0, 1.34}, 0.12), capsule({0, 0, 1.40}, {0, 0, 1.62}, 0.055),
          capsule({-0.10, 0, 1.34}, {-0.70, 0, 1.34}, 0.04), capsule({0.10, 0, 1.34}, {0.70, 0, 1.34}, 0.04)};
}

Scene tshirt_scene(int k) {
  Scene s = tshirt_garment(k);
  s.obstacles.capsules = mannequin_capsules();
  s.self_friction = 0.2;
  s.frames = 90;
  s.render_frames = {0, 30, 90};
  return s;
}

void check_body_clear_of_tshirt(const MeshObstacle& body) {
  constexpr double kClear = 0.01;  // m between the body and a panel at the start
  const Eigen::MatrixX3d& x = body.frames.at(0);
  for (int v = 0; v < x.rows(); ++v) {
    if (!inside_pattern(x(v, 0), x(v, 2) - kHem) || std::abs(x(v, 1)) < kPanelGap - kClear) continue;
    char buf[480];
    std::snprintf(buf, sizeof buf,
                  ": vertex %d (counted from 1; first frame) at (%.3f, %.3f, %.3f) m meets the T-shirt's panels "
                  "where they start (y = +-%.2f m over |x| < %.2f m, %.2f m < z < %.2f m; the body must lie within "
                  "|y| < %.2f m there): place the body in the mannequin's frame (z up, facing +y, torso axis on "
                  "x = y = 0, shoulders at z = 1.34 m) with the collider's \"scale\" and \"translate\" (docs/sim.md)",
                  v + 1, x(v, 0), x(v, 1), x(v, 2), kPanelGap, kSleeveEnd, kHem, kHem + kHeight, kPanelGap - kClear);
    throw std::invalid_argument(body.name + buf);
  }
}

}  // namespace yarnhom::sim
