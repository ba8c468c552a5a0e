#!/usr/bin/env bash
# The measurement floor of "the one-solve step's last frame against Newton's" (issue 38 item 2;
# docs/benchmarks.md, "The one-solve step against Newton"): how far Newton's own last frame moves
# under changes that should not matter physically, beside how far the one-solve step's lies.
# For each material, scene and resolution, `yarnhom sim` runs (90 frames of 1/30 s, --render none):
#   newton        Newton, the reference (on THREADS threads, default 1)
#   newton_sub2   Newton at 1/60 s (--substeps 2; the frames are the same instants)
#   newton_tol10  Newton with a tolerance 10x tighter (--tol TOL_TIGHT)
#   newton_t2     Newton on THREADS_OTHER threads (default 2: only the summation order changes)
#   linearized    the one-solve step
# and any of LINEARIZED_VARIANTS ("NAME=OPTIONS;NAME=OPTIONS", runs named linearized_NAME with
# those options added). Then one table, each run against the reference: rms / max vertex distance
# of the last frame (m), the centre of mass's move (m), the lowest point and the bounding box's
# extents (m), the potential and kinetic energy and largest speed at the last step, and the
# residual force of the last frame (the summary's "residual" line: rms / max over the vertices
# off the colliders of |f| / (m g), f = -grad(E_shell + gravity + colliders)).
#
#   bash scripts/study_one_solve_floor.sh OUT_DIR MATERIAL.h5 [MATERIAL.h5 ...]
#
# Environment: YARNHOM (default build/tools/yarnhom), RESOLUTIONS (default 40: 3,200 triangles;
# 89: 15,842), SCENES (default drape), VARIANTS (default "newton newton_sub2 newton_tol10
# newton_t2 linearized"), TOL_TIGHT (default 2.36e-5 m: a tenth of the drape's default, 1e-2 x the
# 0.707 m rest diagonal x 1/30 s; the hang's sheet is as large), FRAMES (90), SIM_ARGS (more options), JOBS (runs at
# once, default 1), THREADS (--threads of every run but newton_t2, default 1). A run whose
# steps.csv is complete is not run again.
set -euo pipefail
out=$1
shift
y=${YARNHOM:-build/tools/yarnhom}
frames=${FRAMES:-90}
sim_args=${SIM_ARGS:-}
threads=${THREADS:-1}
jobs=${JOBS:-1}
tight=${TOL_TIGHT:-2.36e-5}
variants=${VARIANTS:-newton newton_sub2 newton_tol10 newton_t2 linearized}
declare -A extra=([newton]="--integrator newton" [newton_sub2]="--integrator newton --substeps 2"
  [newton_tol10]="--integrator newton --tol $tight" [newton_t2]="--integrator newton --threads ${THREADS_OTHER:-2}"
  [linearized]="--integrator linearized")
IFS=';' read -r -a lv <<< "${LINEARIZED_VARIANTS:-}"
for e in "${lv[@]}"; do
  [ -n "$e" ] || continue
  extra["linearized_${e%%=*}"]="--integrator linearized ${e#*=}"
  variants="$variants linearized_${e%%=*}"
done
mkdir -p "$out"
run_one() {  # dir, material, scene, resolution, options
  local dir=$1 m=$2 scene=$3 res=$4
  shift 4
  echo "study_one_solve_floor: $dir"
  local t=(--threads "$threads")
  case " $* " in *" --threads "*) t=() ;; esac
  # shellcheck disable=SC2086
  "$y" sim "$scene" -o "$dir" --material "$m" --resolution "$res" --frames "$frames" --render none -q \
    "${t[@]}" $sim_args "$@" > "$dir.log" 2>&1
  echo $? > "$dir.status"
}
for m in "$@"; do
  name=$(basename "$(dirname "$m")")_$(basename "$m" .h5)
  for scene in ${SCENES:-drape}; do
    for res in ${RESOLUTIONS:-40}; do
      for var in $variants; do
        dir="$out/${name}_${scene}_${res}_${var}"
        if [ -f "$dir/steps.csv" ] && [ "$(($(wc -l < "$dir/steps.csv") - 1))" -ge "$frames" ]; then continue; fi
        while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 2; done
        # shellcheck disable=SC2086
        (set +e; run_one "$dir" "$m" "$scene" "$res" ${extra[$var]}) &
      done
    done
  done
done
wait
python3 "$(dirname "$0")/compare_last_frames.py" "$out"
