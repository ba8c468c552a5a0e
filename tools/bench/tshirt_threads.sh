#!/usr/bin/env bash
# The T-shirt benchmark of docs/benchmarks.md ("Garments: the T-shirt with contact") on a
# many-core host: the demo material, then `sim tshirt` at the paper's size (14.7k vertices),
# one-solve steps, on 16 threads and on 2 pinned cores, with --profile's parts per step.
# Usage: tools/bench/tshirt_threads.sh YARNHOM_BINARY OUT_DIR [FRAMES]
set -euo pipefail
bin=$1
out=$2
frames=${3:-10}
mkdir -p "$out"
[ -f "$out/demo/baked.h5" ] || "$bin" pipeline stockinette --preset quick -o "$out/demo" > "$out/pipeline.log" 2>&1
run() {  # tag, threads, BLAS threads, then the command's prefix (taskset ...) if any
  local tag=$1 threads=$2 blas=$3
  shift 3
  echo "== $tag (load $(cut -d' ' -f1-3 /proc/loadavg))"
  "$@" "$bin" sim tshirt --material "$out/demo/baked.h5" --resolution 9 --integrator linearized --frames "$frames" \
    --no-frames --render none --profile --threads "$threads" --blas-threads "$blas" -o "$out/$tag" 2>&1 | tail -n 2
}
run threads16 16 16
run pinned2 2 1 taskset -c 0,1
