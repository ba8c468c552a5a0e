#!/usr/bin/env bash
# The one-solve step against Newton (issue 38; docs/sim.md, "Time stepping"): for each material,
# the drape and hang scenes at 3,200 and about 16k triangles, 90 frames of 1/30 s, run with
# `--integrator linearized` (one solve per step) and `--integrator newton`, then one table:
# exit status, Newton iterations per step, ms per step, the largest speed at the end, the
# energy each run removes per second (total energy, potential + kinetic, first step to last,
# over the simulated time) and how far the one-solve run's last frame lies from Newton's (root
# mean square and largest vertex distance, m).
#
#   bash scripts/study_one_solve.sh OUT_DIR MATERIAL.h5 [MATERIAL.h5 ...]
#
# Environment: YARNHOM (the binary, default build/tools/yarnhom), RESOLUTIONS (default "40 89":
# 3,200 and 15,842 triangles), SCENES (default "drape hang"), INTEGRATORS (default "linearized
# newton"), FRAMES (90), SIM_ARGS (more `yarnhom sim` options, e.g. "--threads 2"). A run whose
# steps.csv is complete is not run again, so an interrupted study resumes.
set -euo pipefail
out=$1
shift
y=${YARNHOM:-build/tools/yarnhom}
read -r -a sim_args <<< "${SIM_ARGS:-}"
frames=${FRAMES:-90}
mkdir -p "$out"
for m in "$@"; do
  name=$(basename "$(dirname "$m")")_$(basename "$m" .h5)
  for scene in ${SCENES:-drape hang}; do
    for res in ${RESOLUTIONS:-40 89}; do
      for integ in ${INTEGRATORS:-linearized newton}; do
        dir="$out/${name}_${scene}_${res}_${integ}"
        if [ -f "$dir/steps.csv" ] && [ "$(($(wc -l < "$dir/steps.csv") - 1))" -ge "$frames" ]; then continue; fi
        echo "study_one_solve: $dir"
        set +e
        "$y" sim "$scene" -o "$dir" --material "$m" --resolution "$res" --integrator "$integ" --frames "$frames" \
          --render none -q "${sim_args[@]}" > "$dir.log" 2>&1
        echo $? > "$dir.status"
        set -e
      done
    done
  done
done
python3 - "$out" <<'EOF'
import csv, glob, math, os, sys
out = sys.argv[1]

def last_frame(d):
    frames = sorted(glob.glob(os.path.join(d, "frames", "frame_*.obj")))
    if not frames:
        return None
    with open(frames[-1]) as f:
        return [tuple(float(t) for t in l.split()[1:4]) for l in f if l.startswith("v ")]

rows = []
for st in sorted(glob.glob(os.path.join(out, "*.status"))):
    d = st[:-len(".status")]
    status = open(st).read().strip()
    steps = list(csv.DictReader(open(os.path.join(d, "steps.csv")))) if os.path.exists(os.path.join(d, "steps.csv")) else []
    if not steps:
        rows.append((os.path.basename(d), status, "", "", "", "", "", ""))
        continue
    its = sum(float(s["newton_iterations"]) for s in steps) / len(steps)
    ms = sum(float(s["wall_ms"]) for s in steps) / len(steps)
    e0 = float(steps[0]["potential_J"]) + float(steps[0]["kinetic_J"])
    e1 = float(steps[-1]["potential_J"]) + float(steps[-1]["kinetic_J"])
    t = float(steps[-1]["time"]) - float(steps[0]["time"])
    removed = (e0 - e1) / t if t > 0 else float("nan")
    dist = ""
    if d.endswith("_linearized"):
        a, b = last_frame(d), last_frame(d[:-len("_linearized")] + "_newton")
        if a and b and len(a) == len(b):
            ds = [math.dist(p, q) for p, q in zip(a, b)]
            dist = "%.4f / %.4f" % (math.sqrt(sum(x * x for x in ds) / len(ds)), max(ds))
    rows.append((os.path.basename(d), status, "%d" % len(steps), "%.2f" % its, "%.1f" % ms,
                 "%.3g" % float(steps[-1]["max_speed_m_per_s"]), "%.3g" % removed, dist))
head = ("run", "exit", "steps", "iterations/step", "ms/step", "max speed at end (m/s)",
        "energy removed (W)", "last frame to Newton's, rms / max (m)")
print("| " + " | ".join(head) + " |")
print("|" + "---|" * len(head))
for r in rows:
    print("| " + " | ".join(r) + " |")
EOF
