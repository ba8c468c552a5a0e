#pragma once
// What each subcommand does: the description its --help prints, by the name the command is
// registered under (tools/cli/cmd_*.cpp; the study subcommands by their own names). In one place,
// as a man page keeps them, so that the registration files hold only their options.
#include <stdexcept>
#include <string>

namespace yarnhom::tools {

struct CommandHelp {
  const char* name;
  const char* text;
};

inline constexpr CommandHelp kCommandHelp[] = {
  {"synth",
   "Write a dataset for all 14 terms sampled from a smooth analytic energy density (written "
   "out in docs/synthetic.md). It stands in for the yarn producer in tests, benchmarks and "
   "the demo; the file says so in its 'source' and 'note' attributes."},
  {"train-all",
   "Train every energy term of a dataset (one MLP per term; by default the paper's 500 Adam "
   "epochs then a full-batch L-BFGS polish, --recipe paper for the paper's recipe exactly), "
   "networks in parallel, and write the model file. The final table shows each term's fit to "
   "its held-out validation points in physical units and says which terms fail the limits "
   "(energy RMSE < 3% of the data range, gradient error < 10% of the mean gradient, gradients "
   "in box coordinates), with the data's own inconsistency beside it ('data G': how far the "
   "data's gradients disagree with the slopes of their energies; no smooth fit does better). Exit "
   "status 2 if a network failed (its loss became non-finite)."},
  {"train",
   "Train one energy term's network (see train-all for the recipe)"},
  {"eval",
   "Evaluate one term of a model at given strains. Prints CSV in physical units (J/m^2, "
   "strains as in the spec): the strain, the energy Psi_I, its gradient, Hessian and third "
   "derivatives with respect to the term's strain components. For a 2D term of a model this "
   "is the term the network stands for in the material, its axis projection N(x,y) - N(x,0) "
   "- N(0,y) + N(0,0), which is what bake bakes (docs/bake.md). MODEL may also be a baked file "
   "(from bake): the same columns from its table, inside or outside the box (safeguard), so "
   "the two can be compared at any strain."},
  {"bake",
   "Bake every network of a model into Hermite tables (1D: cubic, (f, f') at res1d knots; 2D: "
   "bicubic, (f, f_x, f_y, f_xy) on res2d x res2d knots; exact network derivatives) with the "
   "safeguard outside the trained box: a 1D term (energy along one strain axis) continues with "
   "the paper's C2 quadratic, its curvature clamped >= 0, and where its end slope points inward "
   "or curves down the table's outer 5% is repaired so that it rises; a 2D term (a residual, "
   "which may fall outward) is the network's everywhere and continues to first order across "
   "its edges and corners (C1), so that outside the box the total energy's outward curvature "
   "is the 1D terms'. Baked as one material: where a pair's TOTAL energy falls outward at "
   "the box, the 1D end's curvature is raised (C2, in the table's outer 5%) so that it turns "
   "up within half the box width; where a corner's twist would bend the total down without "
   "bound, that corner knot's f_xy is raised (one cell changes). So outside the box the "
   "total is bounded below and rises far out. The table says per term where this departs "
   "from the paper's quadratic and what it changed, and per term pair where the total still "
   "falls outward at the box (data). The baked file is what a cloth simulator loads "
   "(docs/bake.md)."},
  {"error",
   "Metrics of a model or baked file (spec section 9): the quadratic expansion error E_I of "
   "supplement Eq. 5 per term and E of Eq. 4; the fit error against the data (energy and "
   "gradient, absolute and relative); for a baked file its deviation from the network. "
   "--compare adds the supplement Table 4 analogue (bake resolutions against the network)."},
  {"plot",
   "Draw a run's pictures as PNG files: loss curves with the learning rate (supplement Fig. 1), "
   "each 2D term's surface with the safeguard coloured by sector and the magnitude of its third "
   "derivatives (Fig. 3), the sign of the Hessian's smallest eigenvalue (Fig. 4), and data "
   "against network along each 1D term. Needs a python3 with matplotlib and h5py "
   "($YARNHOM_PYTHON, /usr/bin/python3 or python3 on PATH)."},
  {"pipeline",
   "Run the whole pipeline into RUN_DIR: produce (or synth for PATTERN 'synthetic') -> "
   "train-all -> bake -> error -> plot. Each stage is skipped when its output exists, is newer "
   "than its input and was made with the same settings, so a rerun after an interruption "
   "continues. Ends with a short report. Stage logs: RUN_DIR/logs/."},
  {"rve",
   "Solve the periodic yarn RVE of a pattern at one macroscopic strain (docs/rve.md): relaxes "
   "the pattern at rest (yarns and tile period: s = 0 is the stress-free tile), then minimizes "
   "the energy at the strain with Newton's method, every step filtered by collision detection so "
   "that no yarn passes through another. Prints the pattern's and the relaxed periods, Psi0 and "
   "dPsi/ds at rest (the natural bending moment dPsi/dII), the areal density, Psi (J/m^2 of the "
   "relaxed tile), dPsi/ds (envelope theorem), iterations, final residual, time and the topology "
   "certificate. Exit status 2 when the solve does not converge, 3 when the result is not certified."},
  {"produce",
   "Produce the training dataset of a yarn pattern: Psi(s) and dPsi/ds of the periodic yarn RVE "
   "on every term's node grid (spec sections 3-5), solved sector by sector with warm starts "
   "(supplement Algorithm 1). Finished samples go to OUT.partial as they complete, with their "
   "equilibrium states: the same command resumes a killed run to the uninterrupted run's dataset, bit for bit. Exit status 3 when some nodes did not converge (listed). "
   "On several processes or machines: mpirun -np N yarnhom produce ... (a build with MPI): rank 0 hands out the work and "
   "writes the one dataset, the same bytes as one process's; a run whose rank died resumes with any N "
   "(docs/produce.md, 'On a cluster')."},
  {"sim",
   "Simulate cloth with a baked material (thin shell, spec section 10; docs/sim.md). SCENE is a built-in "
   "scene -- drape (a 0.5 m sheet falling onto a sphere), hang (a sheet held by two corners), stretch (a strip "
   "clamped at both ends, 5 cm x 10 cm stretched quasi-statically to 170 % unless --size and --stretch say otherwise) -- or a scene file (JSON). "
   "Writes OUT/frames/frame_NNNN.obj (texture coordinates in [0, 1]; the rest shape in OUT/rest.obj), OUT/steps.csv "
   "(Newton iterations, energies, time per step), PNG renders in OUT/renders/, a video OUT/sim.mp4 (when ffmpeg "
   "is installed) and, for stretch, OUT/stretch.csv and OUT/stretch.png (force per clamp width "
   "in N/m against stretch). Exit status 3 when the simulation becomes non-finite or a triangle leaves every "
   "physical strain (a material whose energy decreases outside its box)."},
  {"export-hylc",
   "Write a baked file in HYLC's material JSON format (density, strain scale, const, 1D and 2D Hermite "
   "splines), which ARCSim-HYLC loads. Every table keeps its knots; the grid is extended beyond each box "
   "by --margin times its width so that the safeguard is reproduced exactly there (HYLC's format "
   "extrapolates linearly beyond its last knot)."},
  {"fit-splines",
   "Fit the HYLC-style spline baseline (Sperl et al. 2020) to a dataset: per term a cubic "
   "Hermite spline with few knots (1D) or a bicubic Hermite patch on a coarse grid (2D), by "
   "least squares on the energies and their gradients with a small curvature penalty; 1D "
   "terms monotone away from their minimum, 2D terms zero on the axes; linear extrapolation "
   "outside the knots. Writes a baked file that sim, eval and export-hylc read like a baked "
   "network (docs/accuracy.md)."},
  {"accuracy",
   "The accuracy test of supplement section 4.2 for one pattern and direction: produce (or "
   "reuse) the dataset, train-all and bake (or reuse) the neural material, fit-splines (the "
   "HYLC-style baseline), the yarn-level strip (strip) and the continuum strip (sim stretch) "
   "for both materials with the same clamps; then per stretch ratio the stress difference "
   "(N/m) and the Hausdorff distance (cm) between the yarn centrelines and the continuum "
   "surface, and their means with the mean relative stress error. Writes OUT/accuracy.csv and "
   "OUT/accuracy.md. Every stage is cached and resumable (logs in OUT/logs)."},
  {"table5",
   "Supplement Table 5: the accuracy test (see `accuracy`) for every pattern and direction, "
   "neural material and spline baseline, written to OUT/table5.md and OUT/table5.csv beside "
   "the paper's figures. Patterns share their dataset and materials across directions."},
  {"bake-resolution",
   "Supplement Table 4: the accuracy test (wale by default) with the same networks baked at "
   "Bake-1 (1D 100 knots, 2D 25x25), Bake-2 (150, 50x50), Bake-3 (200, 100x100) and a "
   "reference bake fine enough to stand for the unbaked network (2000, 400x400: its deviation "
   "from the network is printed by bake), one yarn strip for all. OUT/table4.md and .csv."},
  {"strip-width",
   "Is the gap between a yarn strip and the continuum an edge effect? The accuracy test (see "
   "`accuracy`) on strips of one length and several widths, each yarn strip against a continuum "
   "strip of its own size, one neural material for all. A homogenized model describes the bulk, "
   "so an edge effect shows as a yarn force per width that approaches the continuum's as the "
   "strip widens. OUT/width.md, width.csv and width.png."},
  {"rve-size",
   "Supplement Table 2: datasets produced on periodic patches of n x n tiles of the pattern "
   "(1, 2, 3 by default), each trained, baked and tested against the same yarn strip "
   "(wale by default): production time and mean stress difference. OUT/table2.md and .csv."},
  {"architectures",
   "Supplement Table 3: train the paper's four networks Net-1 [16,16], Net-2 [32,32], Net-3 "
   "[16,32,16] and Net-4 [32,64,32] on one term with the same recipe, seed and split, one after "
   "the other, and print their validation loss (normalized units, as the paper's) and "
   "training time side by side with the paper's figures (basket term 0: 0.232, 0.181, 0.148, "
   "0.197; 83.5-114.3 s on its GPU), with the fit in physical units. Writes OUT/architectures.csv "
   "and OUT/architectures.png."},
  {"strip",
   "Yarn-level fabric strip stretch test (docs/strip.md; supplement section 4.2): tiles a periodic "
   "pattern over a strip of the given size, cuts the yarns at its border, binds the knit off and joins "
   "everything into one yarn with soft boundary yarn (1/200 of the moduli), clamps both short ends and "
   "stretches it quasi-statically, each load step solved to equilibrium by Newton's method with the "
   "RVE's energy (rods, contact kernel and IPC barrier, CCD collision filter). The tile is the pattern's "
   "stress-free relaxed tile (the same rest state as produce). Writes force.csv (clamp force per undeformed width, N/m), the "
   "centrelines of every step (OBJ) and PNGs. Kill it and rerun the same command: finished load steps "
   "are kept. Exit status 2 when a load step does not converge (or, never expected, loses its topology "
   "certificate)."},
};

inline std::string command_help(const std::string& name) {
  for (const CommandHelp& h : kCommandHelp)
    if (name == h.name) return h.text;
  throw std::logic_error("no help text for the command '" + name + "'");
}

}  // namespace yarnhom::tools
