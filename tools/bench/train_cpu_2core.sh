#!/usr/bin/env bash
# The CPU training figures of docs/benchmarks.md ("The polish", 2 cores): train-all on
# `synth --preset paper` with both recipes, back to back, for each given yarnhom binary (e.g. the
# main branch's and this one's), pinned to 2 cores with taskset, --threads 2. Prints, per run,
# the process wall and user time and the load average before it (the cores may be shared).
#   bash tools/bench/train_cpu_2core.sh BINARY... [ROUNDS=2] [CORES=0,1]
set -u -o pipefail
ROUNDS=${ROUNDS:-2}
CORES=${CORES:-0,1}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
"$1" synth --preset paper -o "$W/paper.h5" > /dev/null
for r in $(seq "$ROUNDS"); do
  for bin in "$@"; do
    for recipe in paper default; do
      load=$(cut -d' ' -f1 /proc/loadavg)
      t=$( { /usr/bin/time -f "%e %U" taskset -c "$CORES" "$bin" train-all "$W/paper.h5" -o "$W/m.h5" \
             --threads 2 -q --recipe "$recipe" > "$W/table.txt"; } 2>&1 | tail -1)
      fails=$(grep -c "FAILS" "$W/table.txt")
      printf "round %s  %-40s  recipe %-7s  wall %6s s  user %6s s  load %s  failing terms %s\n" \
        "$r" "$bin" "$recipe" "${t% *}" "${t#* }" "$load" "$fails"
    done
  done
done
