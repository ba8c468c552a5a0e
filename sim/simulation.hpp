#pragma once
// Runs a scene: the time loop (or the quasi-static load steps), the outputs and the figures.
//
// Writes into the output folder, each file complete or not at all (written under a temporary
// name, then renamed), so an interrupted run keeps every finished frame:
//   frames/frame_NNNN.obj   positions of frame NNNN (texture coordinates in [0, 1]: sim/obj_io.hpp)
//   steps.csv               one row per step: Newton iterations, energies, speed, wall time, obstacle lag
//                           and, with profiling, the time split (docs/sim.md lists the columns)
//   stretch.csv             stretch scenes: force per clamp width against stretch
// Frame 0 is the initial state. In a static run frame k is load step k (load parameter k/frames).
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "numerics/sparse_cholesky.hpp"
#include "sim/problem.hpp"
#include "material/material_fn.hpp"
#include "sim/scene.hpp"

namespace yarnhom::sim {

struct SimSettings {
  std::string out_dir;           // "" = write nothing
  // The material's psi alone (material/material_fn.hpp), for the energy evaluations; empty: the
  // material function's psi.
  MaterialValueFn material_value;
  SolverKind solver = SolverKind::Auto;
  double pcg_tolerance = 1e-3;   // --solver pcg / pcg-cuda: relative residual of each solve
  int pcg_max_iterations = 20000;
  HessianModel hessian = HessianModel::Split;  // sim/hessian_model.hpp
  numerics::EigenFilter eigen_filter = numerics::EigenFilter::Clamp;  // numerics/psd_projection.hpp
  bool profile = false;          // time split per step (adds clock reads per element)
  bool write_frames = true;
};

struct StepRecord {
  int step = 0, frame = 0;
  double time = 0;               // s (static: load parameter)
  int iterations = 0;            // Newton iterations (linearized: 1)
  bool converged = true, finite = true;
  int backtracks = 0;
  double potential = 0;          // E_shell + gravity + colliders, J
  double kinetic = 0, max_speed = 0;
  double wall = 0;               // s
  double t_strain = 0, t_material = 0, t_chain = 0, t_project = 0, t_scatter = 0;  // CPU s in the element loop
  double t_assemble = 0, t_solve = 0, t_line_search = 0;                         // wall s
  long projected = 0, elements = 0;
  int factorizations = 0, cg_iterations = 0, reused = 0, evaluations = 0;  // NewtonStats' counts (sim/newton.hpp)
  double obstacle_lag = 0;       // m: the farthest an obstacle point ends the step from where its path puts it
};

struct StretchRow {
  double stretch = 1;            // current length / rest length
  double force = 0;              // reaction of the moving clamp along the axis, N
  double force_per_width = 0;    // N/m (over the undeformed width)
  Strain6 middle_strain = Strain6::Zero();
  double middle_dpsi = 0;        // dPsi/ds along the axis at the middle's strain, N/m
};

struct SimResult {
  bool finite = true;            // no non-finite value anywhere
  std::string diverged;          // non-empty: why the run was stopped (a triangle left every physical strain)
  bool all_converged = true;
  int frames_done = 0;
  std::vector<StepRecord> steps;
  std::vector<StretchRow> stretch;
  Eigen::VectorXd x, v;          // final state, 3n
  Eigen::VectorXd obstacles;     // the obstacles' positions (sim/obstacles.hpp) at that state, 3K
  double kappa = 0;              // the barrier stiffness used
  double friction_eps_v = 0;     // friction's sticking velocity used, m/s
  double tol_step = 0;           // the Newton tolerance used, m
  StepNorm tol_norm = StepNorm::Max;  // ... and the norm it bounds
  int analyses = 0;              // the sparse Cholesky's pattern analyses (numerics/sparse_cholesky.hpp)
  std::string solver_name;       // the linear solver that ran
  long long solver_iterations = 0, solver_solves = 0;  // --solver pcg / pcg-cuda: CG iterations, solves
  // Dynamics: the out-of-balance force of the last state, f = -grad(E_shell + gravity + colliders
  // + contact), per free vertex farther than 2 dhat from every collider (friction may hold a
  // touching vertex), as |f_i| / (m_i g): root mean square and largest; 0 at an equilibrium.
  double residual_rms = NAN, residual_max = NAN;
  int residual_vertices = 0;
};

// Called after every frame with the frame number and the steps so far.
using FrameCallback = std::function<void(int frame, const SimResult&)>;

// What `--solver auto` runs for a scene: the GPU's CG (SolverKind::PcgCuda) for a moving scene
// (any integrator but Static) of kAutoGpuVertices vertices or more when a GPU can run it
// (gpu_usable: the build has CUDA and the machine a device), else Auto (CHOLMOD when the build
// has it). On the H200 host the GPU's CG was the faster at every drape size measured, from 800
// triangles (441 vertices: one-solve step 9.6 ms against 13.7 on 2 cores, Newton 68.5 against
// 89.1) to 16k (124.7 against 336.3; Newton 459.8 against 1,155.6; docs/benchmarks.md, "The
// GPU's CG by size"); a quasi-static stretch keeps the exact factorization its tight tolerance
// needs. Any other kind asked is kept.
inline constexpr int kAutoGpuVertices = 400;
SolverKind resolve_auto_solver(SolverKind asked, const Scene& scene, bool gpu_usable);

// areal_density in kg/m^2 (0 allowed only without gravity and for static runs).
SimResult run_simulation(const Scene& scene, const MaterialFn& material, double areal_density,
                         const SimSettings& settings, const FrameCallback& on_frame = nullptr);

// The first triangle (if any) whose strain is beyond anything cloth survives: |s_x| or |s_y| > 5,
// |s_a| > 0.999 (the yarn directions within 2.6 degrees), or a curvature above 1e4 /m (a radius
// of 0.1 mm). A material whose energy decreases outside its box (a trained model whose boundary
// curvature is negative, extended by the safeguard) lets the solver run there; this names it.
// hinges: the dihedral angles' branches (sim/hinge_angles.hpp), or null for (-pi, pi].
std::optional<std::string> unphysical_strain(const Problem& P, const Eigen::VectorXd& x,
                                             const std::vector<double>* hinges = nullptr);

// The affine map that best carries the prescribed vertices from `from` to `to` (least squares,
// regularized towards the identity where they do not determine it), applied to the free
// vertices: the predictor of a quasi-static load step.
void affine_predictor(const std::vector<int>& prescribed, const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                      Eigen::VectorXd& x);

}  // namespace yarnhom::sim
