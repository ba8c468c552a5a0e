#!/usr/bin/env bash
# The 16k-triangle drape's speed (issue 38, item 5; docs/benchmarks.md, "Drape at 16k
# triangles"): the demo material's drape at resolution 89 (15,842 triangles), each run pinned to
# two cores with taskset, back to back, one table of ms/step and its parts (assembly, solve =
# factorization + triangular solves, line search, rest) averaged over the steps of steps.csv.
# The variants: the one-solve step and Newton, with self-collision on (the drape's default) and
# off, the one-solve step with 2 BLAS threads in the factorization, and Newton with factor reuse
# (`--factor-reuse 8 --factor-reuse-tol 0.1`: CG preconditioned by the step's last factor,
# docs/sim.md; measured not to pay, kept as an option).
#
#   bash scripts/bench_drape_16k.sh OUT_DIR BAKED.h5
#
# Environment: YARNHOM (default build/tools/yarnhom), CORES (default 0,1), FRAMES (default 90),
# VARIANTS (default all: "lin lin-nosc lin-blas2 newton newton-nosc"; also newton-reuse).
set -euo pipefail
out=$1
material=$2
y=${YARNHOM:-build/tools/yarnhom}
cores=${CORES:-0,1}
frames=${FRAMES:-90}
mkdir -p "$out"
for v in ${VARIANTS:-lin lin-nosc lin-blas2 newton newton-nosc}; do
  args=(--integrator linearized)
  case $v in
    lin) ;;
    lin-nosc) args+=(--self-collision off) ;;
    lin-blas2) args+=(--blas-threads 2) ;;
    newton) args=(--integrator newton) ;;
    newton-nosc) args=(--integrator newton --self-collision off) ;;
    newton-reuse) args=(--integrator newton --factor-reuse 8 --factor-reuse-tol 0.1) ;;
    *) echo "bench_drape_16k: unknown variant $v" >&2; exit 2 ;;
  esac
  echo "bench_drape_16k: $v (load $(cut -d' ' -f1-3 /proc/loadavg))" >&2
  set +e
  taskset -c "$cores" "$y" sim drape -o "$out/$v" --material "$material" --resolution 89 --frames "$frames" \
    --threads 2 --render none --no-frames -q --profile "${args[@]}" > "$out/$v.log" 2>&1
  echo $? > "$out/$v.status"
  set -e
done
python3 - "$out" <<'PY'
import csv, glob, os, sys
out = sys.argv[1]
print("| run | exit | steps | iterations/step | factorizations/step | CG iterations/step | ms/step | assembly | solve | line search | rest |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for st in sorted(glob.glob(os.path.join(out, "*.status"))):
    d = st[:-len(".status")]
    f = os.path.join(d, "steps.csv")
    rows = list(csv.DictReader(open(f))) if os.path.exists(f) else []
    if not rows:
        print("| %s | %s | 0 | | | | | | | | |" % (os.path.basename(d), open(st).read().strip()))
        continue
    mean = lambda k: sum(float(r[k]) for r in rows) / len(rows)
    wall, a, s, l = mean("wall_ms"), mean("assemble_ms"), mean("solve_ms"), mean("line_search_ms")
    opt = lambda k: "%.2f" % mean(k) if k in rows[0] else ""
    print("| %s | %s | %d | %.2f | %s | %s | %.0f | %.0f | %.0f | %.0f | %.0f |" % (
        os.path.basename(d), open(st).read().strip(), len(rows), mean("newton_iterations"), opt("factorizations"),
        opt("cg_iterations"), wall, a, s, l, wall - a - s - l))
PY
