// yarnhom sim SCENE -o OUT: simulate cloth with a baked material (or a HYLC material JSON):
// built-in scenes drape, hang, stretch, or a scene file (sim/sim_run.hpp, pipeline/sim_command.hpp).
#include "pipeline/sim_command.hpp"
#include "tools/cli/cli_util.hpp"
#include "tools/cli/stage_checks.hpp"

namespace yarnhom::tools {

namespace {

// The built-in stretch scene's strip.
void add_stretch_options(CLI::App* cmd, sim::SimRunOptions& o) {
  cmd->add_option("--direction", o.direction, "stretch: the strip's long axis, course (x) or wale (y)")
      ->check(CLI::IsMember({"course", "wale"}));
  cmd->add_option("--size", o.size,
                  "stretch: WIDTH,LENGTH of the strip in metres (default 0.05,0.10, the paper's); the default "
                  "resolution is then one quad per 5 mm across")
      ->check(non_empty());
  cmd->add_option("--stretch", o.stretch,
                  "stretch: load steps as 1.0:LAST:STEP, clamp separation / length (default 1.0:1.7:0.05); the strip "
                  "is always relaxed at 100 % first. Replaces --frames")
      ->check(non_empty());
  cmd->add_option("--clamp", o.clamp,
                  "stretch: clamp band at each short end in metres, every vertex within it held (default 0.005, "
                  "as yarnhom strip's --clamp; 0: the end rows only)")
      ->check(finite_non_negative());
}

// Time stepping, the Newton solves and the forces.
void add_integrator_options(CLI::App* cmd, sim::SimRunOptions& o) {
  cmd->add_option("--integrator", o.integrator,
                  "newton (implicit Euler, Newton + line search; default), linearized (one solve per step: one "
                  "Newton iteration of the same step, with its line search), baraff-witkin (ARCSim-HYLC's one-solve "
                  "step, no line search: for comparisons), static (load steps to equilibrium; stretch's default)")
      ->check(CLI::IsMember({"newton", "linearized", "baraff-witkin", "static"}));
  cmd->add_option("--dt", o.dt, "Seconds per frame (default 1/30)")->check(finite_positive());
  cmd->add_option("--substeps", o.substeps, "Time steps per frame (default 1)")->check(CLI::Range(1, 100000));
  cmd->add_option("--frames", o.frames, "Frames to simulate (or load steps for static runs)")->check(CLI::Range(1, 1000000));
  cmd->add_option("--tol", o.tol, "Newton tolerance: size of a Newton step in --tol-norm, m (default: 1e-2 l dt per step for "
                  "dynamics (IPC's velocity criterion), 1e-8 l for statics, l the sheet's rest diagonal; stretch 1e-9)")
      ->check(finite_positive());
  cmd->add_option("--tol-norm", o.tol_norm,
                  "How --tol measures a Newton step: rms (the mass-weighted root mean square of the vertex moves: "
                  "the default for dynamics), max (the largest vertex move, IPC's: the default for statics), auto")
      ->check(CLI::IsMember({"auto", "max", "rms"}));
  cmd->add_option("--max-iterations", o.max_iterations, "Newton iterations per step at most (default 100)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--factor-reuse", o.factor_reuse,
                  "Newton iterations after a step's first solve by conjugate gradients on their own matrix, "
                  "preconditioned by the step's last Cholesky factor, with at most this many CG iterations before "
                  "factoring their own matrix; 0: every iteration factors its own (default 0: measured not to pay on "
                  "the demo's drape, docs/sim.md)")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--factor-reuse-tol", o.factor_reuse_tol,
                  "CG's stop with --factor-reuse: its error estimate (the preconditioned residual) below this "
                  "fraction of the step, in --tol-norm, or below a tenth of --tol (default 1e-2)")
      ->check(CLI::Range(1e-12, 1.0));
  cmd->add_option("--rayleigh-alpha", o.alpha, "Mass-proportional damping, 1/s (default 0)")->check(finite_non_negative());
  cmd->add_option("--rayleigh-beta", o.beta, "Stiffness-proportional damping, s (default 0)")->check(finite_non_negative());
  cmd->add_option("--air", o.air, "Air drag on the normal velocity, kg/(m^2 s) (default 0)")->check(finite_non_negative());
  cmd->add_option("--friction", o.friction,
                  "Coulomb friction coefficient mu between the cloth and every collider, overriding the scene's "
                  "(drape: 0.3; scene files: their \"friction\", else 0; 0 = frictionless). IPC's lagged smooth "
                  "friction: the normal force and tangent plane of each contact taken at the step's start; not "
                  "applied by --integrator baraff-witkin (docs/sim.md)")
      ->check(finite_non_negative());
  cmd->add_option("--self-collision", o.self_collision,
                  "on (default) or off: the cloth's contact with itself (IPC's barrier on point-triangle and "
                  "edge-edge pairs within --dhat, CCD on every step, lagged friction between layers; docs/sim.md). "
                  "Not with --integrator baraff-witkin")
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--dhat", o.dhat,
                  "Barrier activation distance, m, of the colliders and of contact pairs (default 1e-3; scene "
                  "files: \"barrier\": {\"dhat\"})")
      ->check(finite_positive());
  cmd->add_option("--friction-eps-v", o.eps_v,
                  "Friction's sticking velocity threshold eps_v, m/s: below it the friction force ramps smoothly "
                  "from 0 to mu lambda, so static friction is a creep slower than eps_v (default 1e-3 sheet "
                  "diagonals per second)")
      ->check(finite_positive());
  cmd->add_option("--friction-updates", o.friction_updates,
                  "Re-solves of each step with the normal forces and tangent planes taken at its solution "
                  "(IPC's lag updates; default 0: lagged at the step's start)")
      ->check(CLI::Range(0, 100));
}

// The linear solves, threads and outputs.
void add_solver_options(CLI::App* cmd, sim::SimRunOptions& o) {
  cmd->add_option("--solver", o.solver,
                  "Linear solver of the steps: auto (pcg-cuda for a moving scene of 400 vertices or more when this build "
                  "has CUDA and a GPU is there, else CHOLMOD when built with it), ldlt (Eigen), cholmod, pcg "
                  "(block-Jacobi preconditioned conjugate gradients on the CPU, to --pcg-tolerance) or pcg-cuda (the "
                  "same on the GPU, in builds with CUDA: at 16k triangles a solve of about 10 ms against CHOLMOD's "
                  "~160 ms on 2 cores; docs/sim.md, \"Linear solvers\")")
      ->check(CLI::IsMember({"auto", "ldlt", "cholmod", "pcg", "pcg-cuda"}));
  cmd->add_option("--pcg-tolerance", o.pcg_tolerance,
                  "--solver pcg / pcg-cuda: relative residual |b - A x| / |b| at which a solve stops (default 1e-3; "
                  "an early stop is a shorter Newton step, which the line search takes as it is)")
      ->check(CLI::Range(1e-12, 0.5));
  cmd->add_option("--hessian", o.hessian,
                  "PSD model of each element's Hessian for the Newton solves (and the linearized integrator's "
                  "stiffness): split (default: the material's 6x6 d2Psi/ds2 and the in-plane curvature term "
                  "projected, the bending curvature term left out; about 3x cheaper to assemble, as few Newton "
                  "iterations on the drapes measured) or projected (the exact 18x18 element Hessian projected onto "
                  "the PSD cone); docs/sim.md")
      ->check(CLI::IsMember({"projected", "split"}));
  cmd->add_option("--eigen-filter", o.eigen_filter,
                  "What the PSD model makes of a negative eigenvalue: clamp (default: zero, the projection onto the "
                  "PSD cone, IPC's) or abs (its absolute value, Chen et al. 2024: on a curling stockinette's hang "
                  "7.8 -> 4.7 Newton iterations per step, but a draped sheet keeps creeping at 2-4 cm/s); docs/sim.md")
      ->check(CLI::IsMember({"abs", "clamp"}));
  add_threads_option(cmd, o.threads, "Threads for the element loop (default: all cores)", 1);
  cmd->add_option("--blas-threads", o.blas_threads,
                  "Threads of OpenBLAS inside CHOLMOD's factorization (default 1: on a machine of few shared cores "
                  "its spinning workers slow the element loop more than they speed the factorization; "
                  "docs/benchmarks.md). Ignored with the reference BLAS")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--render", o.render, "Frames to draw as PNG, e.g. 0,30,90, or none (default: the scene's); unless none, also OUT/sim.mp4 of every frame (with ffmpeg installed)");
  cmd->add_flag("--no-frames", o.no_frames, "Do not write an OBJ per frame (timing runs)");
  cmd->add_flag("--profile", o.profile, "Time each step's parts: assembly, solve, line search and the rest, the element loop's CPU time (strain, material, chain rule, projection), and the named parts in ms per step with their calls per step (the elements' derivatives, the contact terms, the broad phase's region builds, the CCD, the solver's build, upload and iterations; docs/sim.md, Outputs)");
  add_quiet_flag(cmd, o.quiet, "No progress line");
}

}  // namespace

namespace {

// sim's options into o.
CLI::App* declare_sim(CLI::App& app, const std::shared_ptr<sim::SimRunOptions>& op) {
  CLI::App* cmd = app.add_subcommand("sim", command_help("sim"));
  sim::SimRunOptions* o = op.get();
  cmd->add_option("SCENE", o->scene, "drape, hang, stretch, fold, tshirt, or a scene file (.json)")->required();
  add_output_option(cmd, o->out, "Output folder (created)");
  cmd->add_option("--material", o->material,
                  "Baked file (yarnhom bake) or HYLC material JSON; required unless the scene file names one")
      ->check(existing_regular_file());
  cmd->add_option("--density", o->density,
                  "Areal density in kg/m^2 (default: the scene file's, else the material's; required for gravity "
                  "when neither has one)")
      ->check(finite_positive());
  cmd->add_option("--resolution", o->resolution,
                  "Built-in scenes: quads along the sheet's side (drape 40, hang 30, fold 24) or across the strip "
                  "(stretch 10); tshirt: grid refinement k, spacing 8 cm / k (default 4: 3,010 vertices; 9: 14.7k, the paper's size)")
      ->check(CLI::Range(1, 2000));
  cmd->add_option("--body", o->body,
                  "tshirt: a body OBJ (metres, a static triangle mesh) that wears the T-shirt instead of the mannequin "
                  "of capsules; it must stand in the mannequin's frame: z up, facing +y, torso axis on x = y = 0, "
                  "arms held out sideways at z = 1.34 m, clear of the panels (|y| < 0.15 m under them); friction 0.3. "
                  "To scale, move or animate it, use a scene file (docs/sim.md, \"Garments\")")
      ->check(existing_regular_file());
  add_stretch_options(cmd, *o);
  add_integrator_options(cmd, *o);
  add_solver_options(cmd, *o);
  return cmd;
}

}  // namespace

void register_sim(CLI::App& app) {
  auto o = std::make_shared<sim::SimRunOptions>();
  CLI::App* cmd = declare_sim(app, o);
  cmd->callback([o] { exit_with(pipeline::run_sim_command(*o)); });
}

void check_sim_stage(const std::vector<std::string>& args) {
  CLI::App app;
  auto o = std::make_shared<sim::SimRunOptions>();
  declare_sim(app, o)->callback([o] { sim::check_sim_options(*o); });
  parse_stage(app, args);
}

}  // namespace yarnhom::tools
