#include "sim/simulation.hpp"

#include <algorithm>
#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "core/atomic_file.hpp"
#include "core/scope_profile.hpp"
#include "sim/contact.hpp"
#include "sim/contact_pattern.hpp"
#include "sim/garment.hpp"
#include "sim/hinge_angles.hpp"
#include "sim/integrators.hpp"
#include "sim/obj_io.hpp"
#include "sim/potential.hpp"
#include "sim/shell_energy.hpp"

namespace yarnhom::sim {

namespace fs = std::filesystem;

void affine_predictor(const std::vector<int>& prescribed, const Eigen::VectorXd& from_in, const Eigen::VectorXd& to,
                      Eigen::VectorXd& x) {
  if (prescribed.empty()) return;
  const Eigen::VectorXd from = from_in;  // x may be from_in
  Eigen::Vector3d pm = Eigen::Vector3d::Zero(), qm = Eigen::Vector3d::Zero();
  for (int v : prescribed) {
    pm += from.segment<3>(3 * v);
    qm += to.segment<3>(3 * v);
  }
  pm /= double(prescribed.size());
  qm /= double(prescribed.size());
  Eigen::Matrix3d PP = Eigen::Matrix3d::Zero(), QP = Eigen::Matrix3d::Zero();
  for (int v : prescribed) {
    const Eigen::Vector3d p = from.segment<3>(3 * v) - pm, q = to.segment<3>(3 * v) - qm;
    PP += p * p.transpose();
    QP += q * p.transpose();
  }
  const double eps = 1e-8 * (PP.trace() + 1e-300);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d A = (QP + eps * I) * (PP + eps * I).inverse();
  const Eigen::Vector3d b = qm - A * pm;
  std::vector<char> fixed(from.size() / 3, 0);
  for (int v : prescribed) fixed[v] = 1;
  for (size_t v = 0; v < fixed.size(); ++v)
    if (!fixed[v]) x.segment<3>(3 * v) = A * from.segment<3>(3 * v) + b;
}

std::optional<std::string> unphysical_strain(const Problem& P, const Eigen::VectorXd& x, const std::vector<double>* hinges) {
  const std::vector<Strain6> s = triangle_strains(P.mesh, P.rest, x, hinges && !hinges->empty() ? hinges->data() : nullptr);
  // The first triangle beyond the limits, found on the threads (a T-shirt's 28,512 triangles:
  // the scan with its hypot took about 1 ms on one thread, every step).
  auto beyond = [](const Strain6& e) {
    const double r = std::hypot(0.5 * (e[3] - e[5]), e[4]), m = 0.5 * std::abs(e[3] + e[5]);
    return std::abs(e[0]) > 5 || std::abs(e[2]) > 5 || std::abs(e[1]) > 0.999 || m + r > 1e4 || !e.allFinite();
  };
  const int64_t nt = int64_t(s.size());
  int64_t first = nt;
#pragma omp parallel for schedule(static) reduction(min : first) if (nt >= 4096)
  for (int64_t t = 0; t < nt; ++t)
    if (t < first && beyond(s[size_t(t)])) first = t;
  for (size_t t = size_t(first); t < s.size(); ++t) {
    const Strain6& e = s[t];
    if (beyond(e)) {
      // Which of the two usual causes: an energy below rest there means the material falls
      // outside its box (the safeguard should prevent it); above rest, the step overshot.
      const double psi = P.material(e).psi, rest = P.material(Strain6::Zero()).psi;
      char buf[600];
      std::snprintf(buf, sizeof buf,
                    "triangle %zu reached s = (%.4g, %.4g, %.4g, %.4g, %.4g, %.4g), beyond any physical strain, where the "
                    "material's energy is %.6g J/m^2 (%.6g at rest): %s",
                    t, e[0], e[1], e[2], e[3], e[4], e[5], psi, rest,
                    !(psi >= rest) ? "the material decreases outside its box in that direction (check the terms with "
                                     "`yarnhom eval`; bake it again with this yarnhom's bake)"
                                   : "the energy rises there, so the time step overshot (try --substeps 2 or a smaller --dt; "
                                     "the baraff-witkin integrator has no line search: --integrator linearized has one)");
      return std::string(buf);
    }
  }
  return std::nullopt;
}

namespace {

using Clock = std::chrono::steady_clock;

std::string frame_path(const std::string& dir, int frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "frame_%04d.obj", frame);
  return (fs::path(dir) / "frames" / buf).string();
}

void write_stretch_csv(const std::string& path, const std::vector<StretchRow>& rows, const char* dpsi_name) {
  AtomicOutput out(path);
  FILE* f = std::fopen(out.temp_path().c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot write");
  std::fprintf(f, "stretch,force_N,force_per_width_N_per_m,middle_s_x,middle_s_a,middle_s_y,middle_II_x,middle_II_a,middle_II_y,middle_%s_N_per_m\n",
               dpsi_name);
  for (const StretchRow& r : rows) {
    std::fprintf(f, "%.6f,%.9g,%.9g", r.stretch, r.force, r.force_per_width);
    for (int k = 0; k < 6; ++k) std::fprintf(f, ",%.9g", r.middle_strain[k]);
    std::fprintf(f, ",%.9g\n", r.middle_dpsi);
  }
  if (std::fclose(f) != 0) throw std::runtime_error(path + ": write failed");
  out.commit();
}

// The rest mesh's bounding-box diagonal (m): the scale of the default tolerances.
double rest_diagonal(const Mesh& mesh) {
  return (mesh.rest.colwise().maxCoeff() - mesh.rest.colwise().minCoeff()).norm();
}

// The potential's problem for a scene: the material, density, colliders, barrier and friction
// parameters, damping and Hessian model, each checked.
Problem scene_problem(const Scene& scene, const MaterialFn& material, double density, const SimSettings& set) {
  const bool dynamic = scene.integrator != Integrator::Static;
  if (!(density >= 0) || !std::isfinite(density)) throw std::invalid_argument("areal density must be >= 0");
  if (dynamic && !(density > 0))
    throw std::invalid_argument("a dynamic simulation needs a positive areal density (kg/m^2)");
  if (scene.gravity.norm() > 0 && !(density > 0))
    throw std::invalid_argument("gravity needs a positive areal density (kg/m^2)");
  Problem P = make_problem(scene.mesh, material, density);
  P.material_value = set.material_value;
  P.gravity = scene.gravity;
  P.colliders = scene.colliders;
  P.dhat = scene.dhat;
  const double weight = density * scene.gravity.norm();
  P.kappa = scene.kappa > 0 ? scene.kappa : (weight > 0 ? 100 * weight : 1.0);
  P.rayleigh_alpha = scene.rayleigh_alpha;
  P.rayleigh_beta = scene.rayleigh_beta;
  P.air_drag = scene.air_drag;
  P.hessian = set.hessian;
  P.eigen_filter = set.eigen_filter;
  for (const Collider& c : P.colliders)
    if (!(c.friction >= 0) || !std::isfinite(c.friction)) throw std::invalid_argument("a collider's friction must be >= 0");
  // Friction's sticking velocity: IPC's default, 1e-3 sheet sizes per second.
  P.friction_eps_v = scene.friction_eps_v > 0 ? scene.friction_eps_v : 1e-3 * rest_diagonal(P.mesh);
  P.friction_updates = scene.friction_updates;
  P.obstacles = scene.obstacles;
  finish_obstacles(P.obstacles);
  P.self_collision = scene.self_collision;
  P.self_friction = std::max(0.0, scene.self_friction);
  // ARCSim-HYLC's step has no barrier: no self-collision there, and no surface colliders.
  if (scene.integrator == Integrator::BaraffWitkin) {
    P.self_collision = false;
    if (!P.obstacles.empty())
      throw std::invalid_argument("the baraff-witkin integrator has no contact handling: capsule and mesh colliders need "
                                  "--integrator newton or linearized");
  }
  if (has_contact(P)) P.edges = cloth_edges(P.mesh);
  // Seams: each stitch's starting offset, and the stitched vertices' shared representatives.
  P.stitches = scene.stitches;
  for (Stitch& st : P.stitches) {
    if (st.a < 0 || st.b < 0 || st.a >= P.mesh.num_vertices() || st.b >= P.mesh.num_vertices() || st.a == st.b)
      throw std::invalid_argument("a seam's stitch joins vertices " + std::to_string(st.a) + " and " + std::to_string(st.b) +
                                  ": each must be a vertex of the mesh, and they must differ");
    st.offset0 = (P.mesh.x.row(st.a) - P.mesh.x.row(st.b)).transpose();
  }
  P.stitch_stiffness = scene.stitch_stiffness;
  P.sew_time = scene.sew_time;
  P.gravity_delay = scene.gravity_delay;
  if (!P.stitches.empty()) P.vertex_rep = stitch_representatives(P.mesh.num_vertices(), P.stitches);
  return P;
}

// Vertices must start outside the colliders (the barrier is infinite inside).
void require_outside_colliders(const Problem& P, const Eigen::VectorXd& x0) {
  for (int v = 0; v < P.mesh.num_vertices(); ++v)
    for (size_t c = 0; c < P.colliders.size(); ++c)
      if (!(collider_distance(P.colliders[c], x0.segment<3>(3 * v)) > 0))
        throw std::invalid_argument("vertex " + std::to_string(v) + " starts inside collider " + std::to_string(c));
}

// With contact, the start must be free of intersections and every pair beyond its d_min.
void require_contact_free_start(const Problem& P, const Eigen::VectorXd& x0) {
  if (!has_contact(P)) return;
  const Eigen::VectorXd y = obstacle_positions(P.obstacles, 0.0);
  std::string what;
  if (contact_intersections(P, x0, y, &what))
    throw std::invalid_argument("the cloth starts intersecting: " + what +
                                (P.self_collision ? " (self-collision needs a start without; --self-collision off ignores it)" : ""));
  if (!std::isfinite(contact_energy(P, {}, x0, y)))
    throw std::invalid_argument("the cloth starts touching an obstacle or itself (a contact pair at or below its minimum distance)");
}

// OUT/frames/ and OUT/steps.csv with its header.
FILE* open_steps_csv(const std::string& dir) {
  fs::create_directories(fs::path(dir) / "frames");
  FILE* csv = std::fopen((fs::path(dir) / "steps.csv").c_str(), "w");
  if (!csv) throw std::runtime_error(dir + "/steps.csv: cannot write");
  std::fprintf(csv, "step,frame,time,newton_iterations,converged,backtracks,potential_J,kinetic_J,max_speed_m_per_s,wall_ms,"
                    "strain_cpu_ms,material_cpu_ms,chain_cpu_ms,project_cpu_ms,scatter_cpu_ms,projected_elements,"
                    "assemble_ms,solve_ms,line_search_ms,factorizations,cg_iterations,reused_iterations,energy_evaluations,"
                    "obstacle_lag_m\n");
  return csv;
}

void write_step_row(FILE* csv, const StepRecord& rec) {
  std::fprintf(csv, "%d,%d,%.9g,%d,%d,%d,%.12g,%.12g,%.9g,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%ld,%.4f,%.4f,%.4f,%d,%d,%d,%d,%.6g\n", rec.step,
               rec.frame, rec.time, rec.iterations, int(rec.converged), rec.backtracks, rec.potential, rec.kinetic,
               rec.max_speed, 1e3 * rec.wall, 1e3 * rec.t_strain, 1e3 * rec.t_material, 1e3 * rec.t_chain,
               1e3 * rec.t_project, 1e3 * rec.t_scatter, rec.projected, 1e3 * rec.t_assemble, 1e3 * rec.t_solve,
               1e3 * rec.t_line_search, rec.factorizations, rec.cg_iterations, rec.reused, rec.evaluations,
               rec.obstacle_lag);
  std::fflush(csv);
}

// A step's Newton statistics and timings, and its energies where the step stayed finite.
// The potential energy is evaluated on the hinges' carried branches (a hinge past pi would
// otherwise count on (-pi, pi] and the energy jump).
void record_step(StepRecord& rec, const StepStats& st, const Problem& P, const DofMap& D, const Eigen::VectorXd& x,
                 const Eigen::VectorXd& v, const std::vector<double>& hinges) {
  rec.iterations = st.newton.iterations;
  rec.converged = st.newton.converged;
  rec.backtracks = st.newton.backtracks;
  rec.finite = st.finite;
  rec.t_strain = st.newton.shell.strain;
  rec.t_material = st.newton.shell.material;
  rec.t_chain = st.newton.shell.chain;
  rec.t_project = st.newton.shell.project;
  rec.t_scatter = st.newton.shell.scatter;
  rec.projected = st.newton.shell.projected;
  rec.elements = st.newton.shell.elements;
  rec.t_assemble = st.newton.t_assemble;
  rec.t_solve = st.newton.t_solve;
  rec.t_line_search = st.newton.t_line_search;
  rec.factorizations = st.newton.factorizations;
  rec.cg_iterations = st.newton.cg_iterations;
  rec.reused = st.newton.reused;
  rec.evaluations = st.newton.evaluations;
  if (st.finite) {
    if (std::isfinite(st.newton.shell_energy)) {
      // The solver's last pass evaluated E_shell at x (on the same branches): only the
      // per-vertex terms remain.
      rec.potential = st.newton.shell_energy + external_potential(P, x);
    } else {
      StepState none;
      none.dynamic = false;
      none.theta_ref = hinges;
      rec.potential = potential_value(P, D, none, x);
    }
    double kin = 0, vmax = 0;
    for (int i = 0; i < P.mesh.num_vertices(); ++i) {
      const double s2 = v.segment<3>(3 * i).squaredNorm();
      kin += 0.5 * P.mass[i] * s2;
      vmax = std::max(vmax, std::sqrt(s2));
    }
    rec.kinetic = kin;
    rec.max_speed = vmax;
  }
}

// SimResult::residual_*: the last state's out-of-balance force per vertex weight, off the colliders,
// with the forces of the last step's time (the seams' rest gaps, which close over the sewing).
void last_state_residual(const Problem& P, const DofMap& D, const HessianPattern& pat, const std::vector<double>& hinges,
                         SimResult& R) {
  const double g = P.gravity.norm();
  if (!(g > 0) || !R.x.allFinite()) return;
  StepState S;
  S.dynamic = false;
  S.theta_ref = hinges;
  S.obstacle_y = R.obstacles;
  if (!R.steps.empty()) S.time = R.steps.back().time;
  Eigen::VectorXd grad = Eigen::VectorXd::Zero(R.x.size());
  potential_derivatives(P, D, pat, S, R.x, grad, nullptr);
  double sum = 0, mx = 0;
  int n = 0;
  for (int i = 0; i < D.num_free(); ++i) {
    const int v = D.free_vertices[i];
    bool near = false;
    for (const Collider& c : P.colliders) near = near || collider_distance(c, R.x.segment<3>(3 * v)) < 2 * P.dhat;
    if (near || !(P.mass[v] > 0)) continue;
    const double r = grad.segment<3>(3 * v).norm() / (P.mass[v] * g);
    sum += r * r;
    mx = std::max(mx, r);
    ++n;
  }
  R.residual_vertices = n;
  if (n > 0) {
    R.residual_rms = std::sqrt(sum / n);
    R.residual_max = mx;
  }
}

}  // namespace

SolverKind resolve_auto_solver(SolverKind asked, const Scene& scene, bool gpu_usable) {
  if (asked != SolverKind::Auto || !gpu_usable) return asked;
  if (scene.integrator == Integrator::Static || scene.mesh.num_vertices() < kAutoGpuVertices) return asked;
  return SolverKind::PcgCuda;
}

SimResult run_simulation(const Scene& scene, const MaterialFn& material, double density, const SimSettings& set,
                         const FrameCallback& on_frame) {
  const bool dynamic = scene.integrator != Integrator::Static;
  Problem P = scene_problem(scene, material, density, set);
  const double diag = rest_diagonal(P.mesh);
  const std::vector<int> prescribed = prescribed_vertices(scene.handles);
  const DofMap D = make_dof_map(P.mesh.num_vertices(), prescribed);
  HessianPattern pat = make_hessian_pattern(P.mesh, D);
  if (P.self_collision) pat.contact = std::make_shared<PaddedPattern>();
  LinearSolver solver(set.solver);
  solver.set_iterative(set.pcg_tolerance, set.pcg_max_iterations);

  const Eigen::VectorXd x0 = flatten(P.mesh.x);
  require_outside_colliders(P, x0);
  require_contact_free_start(P, x0);
  SimResult R;
  R.kappa = P.kappa;
  R.friction_eps_v = P.friction_eps_v;
  R.x = x0;
  R.v = Eigen::VectorXd::Zero(x0.size());
  const std::string& dir = set.out_dir;
  FILE* csv = dir.empty() ? nullptr : open_steps_csv(dir);
  // The hinges' dihedral angles on their continuous branch, carried from step to step.
  std::vector<double> hinges = hinge_angles(P.mesh, x0);
  const int stretch_index = std::abs(scene.stretch.axis.y()) > std::abs(scene.stretch.axis.x()) ? 2 : 0;
  const int middle = scene.stretch.enabled ? triangle_at(P.mesh, scene.stretch.middle) : -1;
  auto stretch_row = [&](const Eigen::VectorXd& x, double t) {
    StretchRow row;
    const Handle& h = scene.handles.at(scene.stretch.moving_handle);
    row.stretch = 1 + handle_offset(h, t).dot(scene.stretch.axis) / scene.stretch.length;
    const Eigen::VectorXd g = potential_energy_gradient(P, x);
    for (int v : h.vertices) row.force += g.segment<3>(3 * v).dot(scene.stretch.axis);
    row.force_per_width = row.force / scene.stretch.width;
    row.middle_strain = triangle_strains(P.mesh, P.rest, x, hinges.data())[middle];
    row.middle_dpsi = material(row.middle_strain).grad[stretch_index];
    return row;
  };
  const double h = scene.dt / scene.substeps;
  NewtonSettings nopt = scene.newton;
  if (!(nopt.tol_step > 0)) {
    // IPC's: a velocity error of 1e-2 rest diagonals per second; statics: 1e-8 diagonals.
    nopt.tol_step = dynamic ? 1e-2 * diag * h : 1e-8 * diag;
  }
  // Dynamics: that velocity error as the mass-weighted mean over the sheet (sim/newton.hpp);
  // statics: at every vertex.
  if (nopt.norm == StepNorm::Auto) nopt.norm = dynamic ? StepNorm::MassRms : StepNorm::Max;
  R.tol_step = nopt.tol_step;
  R.tol_norm = nopt.norm;
  if (!dynamic) {
    // A quasi-static load path starts in equilibrium: the sheet relaxes at load 0 first (a
    // material with a natural bending moment curls, one with a rest stress settles), as the
    // yarn strip relaxes at 100 % before it is stretched. Before, frame 0 and the first
    // stretch row were the undeformed mesh.
    const Eigen::VectorXd target = handle_targets(scene.handles, x0, 0.0);
    const Eigen::VectorXd previous = R.x;
    const StepStats st0 = static_solve(P, D, pat, solver, R.x, target, nopt, set.profile, &hinges, &previous);
    R.finite = R.finite && st0.finite;
    R.all_converged = R.all_converged && st0.newton.converged;
    if (!R.finite) {
      if (csv) std::fclose(csv);
      return R;
    }
  }
  if (!dir.empty() && set.write_frames) write_obj(frame_path(dir, 0), P.mesh, unflatten(R.x));
  if (scene.stretch.enabled) {
    R.stretch.push_back(stretch_row(R.x, 0.0));
    if (!dir.empty()) write_stretch_csv((fs::path(dir) / "stretch.csv").string(), R.stretch, stretch_index ? "dPsi_ds_y" : "dPsi_ds_x");
  }
  int step = 0;
  double last_potential = NAN;  // the recorded potential energy at x (spares the next step a pass)
  Eigen::VectorXd& x = R.x;
  Eigen::VectorXd& v = R.v;
  ObstacleMotion motion;  // the obstacles' positions, carried from step to step
  motion.y = obstacle_positions(P.obstacles, 0.0);
  R.obstacles = motion.y;
  for (int frame = 1; frame <= scene.frames; ++frame) {
    const int nsub = dynamic ? scene.substeps : 1;
    for (int k = 0; k < nsub; ++k) {
      ++step;
      StepRecord rec;
      rec.step = step;
      rec.frame = frame;
      const auto t0 = Clock::now();
      StepStats st;
      if (dynamic) {
        rec.time = step * h;
        const Eigen::VectorXd target = handle_targets(scene.handles, x0, rec.time);
        motion.target = obstacle_positions(P.obstacles, rec.time);
        motion.time = rec.time;
        if (scene.integrator == Integrator::Newton)
          st = implicit_euler_step(P, D, pat, solver, x, v, target, h, nopt, set.profile, &hinges, last_potential, &motion);
        else if (scene.integrator == Integrator::Linearized)
          st = linearized_step(P, D, pat, solver, x, v, target, h, nopt, set.profile, &hinges, last_potential, &motion);
        else
          st = baraff_witkin_step(P, D, pat, solver, x, v, target, h, set.profile, &hinges);
      } else {
        rec.time = double(frame) / scene.frames;
        const Eigen::VectorXd target = handle_targets(scene.handles, x0, rec.time);
        const Eigen::VectorXd previous = x;  // friction's displacement is measured from the last equilibrium
        affine_predictor(prescribed, x, target, x);
        st = static_solve(P, D, pat, solver, x, target, nopt, set.profile, &hinges, &previous);
      }
      rec.wall = std::chrono::duration<double>(Clock::now() - t0).count();
      {
        prof::Scope ps("after the step: its record");
        record_step(rec, st, P, D, x, v, hinges);
      }
      R.obstacles = motion.y;
      // An obstacle the cloth held back (CCD left no safe move) lags behind its path.
      if (dynamic && scene.integrator != Integrator::BaraffWitkin && motion.target.size() == motion.y.size())
        for (Eigen::Index k = 0; k + 2 < motion.y.size(); k += 3)
          rec.obstacle_lag = std::max(rec.obstacle_lag, (motion.y.segment<3>(k) - motion.target.segment<3>(k)).norm());
      last_potential = rec.potential;
      R.finite = R.finite && st.finite && std::isfinite(rec.potential);
      if (R.finite) {
        prof::Scope ps("after the step: strain check");
        if (auto why = unphysical_strain(P, x, &hinges)) R.diverged = *why;
      }
      R.all_converged = R.all_converged && rec.converged;
      R.analyses = solver.analyses();
      R.solver_name = solver.name();
      R.solver_iterations = solver.iterations();
      R.solver_solves = solver.solves();
      R.steps.push_back(rec);
      if (csv) {
        write_step_row(csv, rec);
      }
      if (!R.finite || !R.diverged.empty()) break;
    }
    if (!R.finite || !R.diverged.empty()) break;
    R.frames_done = frame;
    if (scene.stretch.enabled) {
      R.stretch.push_back(stretch_row(x, double(frame) / scene.frames));
      if (!dir.empty())
        write_stretch_csv((fs::path(dir) / "stretch.csv").string(), R.stretch, stretch_index ? "dPsi_ds_y" : "dPsi_ds_x");
    }
    if (!dir.empty() && set.write_frames) write_obj(frame_path(dir, frame), P.mesh, unflatten(x));
    if (on_frame) on_frame(frame, R);
  }
  if (csv) std::fclose(csv);
  if (dynamic && R.finite) last_state_residual(P, D, pat, hinges, R);
  return R;
}

}  // namespace yarnhom::sim
