#!/usr/bin/env bash
# The contact step's speed before/after a change, on the many-core GPU host (docs/benchmarks.md,
# "Drape at 16k triangles: the speed targets"): the demo material's one-solve drape at 16k
# triangles pinned to 2 cores (both binaries side by side on their own core pairs, with
# self-collision and without), the same drape alone on 16 threads (BLAS 8), and the T-shirt at
# the paper's size (`sim tshirt --resolution 9`, 14.7k vertices) alone on 16 threads. Prints one
# table of ms/step and its parts (steps.csv means).
#
#   bash tools/bench/step_threads.sh BEFORE_YARNHOM AFTER_YARNHOM BAKED.h5 OUT_DIR [FRAMES]
#
# FRAMES: 30 by default (the T-shirt runs 10).
set -euo pipefail
before=$1
after=$2
material=$3
out=$4
frames=${5:-30}
mkdir -p "$out"
here=$(cd "$(dirname "$0")/../.." && pwd)
echo "step_threads: pinned pairs (load $(cut -d' ' -f1-3 /proc/loadavg))" >&2
VARIANTS="lin lin-nosc" CORES=0,1 FRAMES=$frames YARNHOM=$before bash "$here/scripts/bench_drape_16k.sh" "$out/pinned2_before" "$material" > "$out/pinned2_before.md" &
VARIANTS="lin lin-nosc" CORES=2,3 FRAMES=$frames YARNHOM=$after bash "$here/scripts/bench_drape_16k.sh" "$out/pinned2_after" "$material" > "$out/pinned2_after.md" &
wait
run() {  # tag, binary, scene args...
  local tag=$1 bin=$2
  shift 2
  echo "step_threads: $tag (load $(cut -d' ' -f1-3 /proc/loadavg))" >&2
  set +e
  taskset -c 0-15 "$bin" sim "$@" -o "$out/$tag" --render none --no-frames -q --profile --integrator linearized \
    > "$out/$tag.log" 2>&1
  echo $? > "$out/$tag.status"
  set -e
}
for round in 1 2; do
  for which in before after; do
    bin=$before
    [ "$which" = after ] && bin=$after
    run "drape16_${which}_$round" "$bin" drape --material "$material" --resolution 89 --frames "$frames" --threads 16 --blas-threads 8
    run "tshirt16_${which}_$round" "$bin" tshirt --material "$material" --resolution 9 --frames 10 --threads 16 --blas-threads 16
  done
done
echo "pinned to 2 cores, before:"
cat "$out/pinned2_before.md"
echo "pinned to 2 cores, after:"
cat "$out/pinned2_after.md"
python3 - "$out" <<'PY'
import csv, glob, os, sys
out = sys.argv[1]
print("| run (16 threads) | exit | steps | ms/step | assembly | solve | line search | rest |")
print("|---|---|---|---|---|---|---|---|")
for st in sorted(glob.glob(os.path.join(out, "*16_*.status"))):
    d = st[:-len(".status")]
    f = os.path.join(d, "steps.csv")
    rows = list(csv.DictReader(open(f))) if os.path.exists(f) else []
    if not rows:
        print("| %s | %s | 0 | | | | | |" % (os.path.basename(d), open(st).read().strip()))
        continue
    mean = lambda k: sum(float(r[k]) for r in rows) / len(rows)
    wall, a, s, l = mean("wall_ms"), mean("assemble_ms"), mean("solve_ms"), mean("line_search_ms")
    print("| %s | %s | %d | %.0f | %.0f | %.0f | %.0f | %.0f |" % (
        os.path.basename(d), open(st).read().strip(), len(rows), wall, a, s, l, wall - a - s - l))
PY
