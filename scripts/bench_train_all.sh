#!/usr/bin/env bash
# The train-all benchmark of docs/benchmarks.md: `yarnhom train-all` on `synth --preset paper`
# (14 networks) with the default recipe (500 epochs + L-BFGS polish: the speed target) and
# with the paper's recipe (500 epochs), against the PyTorch reference of the paper's recipe on
# the same machine in the same run (EPOCHS epochs per network, extrapolated to 500; the ratio
# compares like with like: the paper's recipe on both sides).
# Usage: bash scripts/bench_train_all.sh [BUILD_DIR] [EPOCHS] [THREADS]
set -euo pipefail
build=${1:-build}
epochs=${2:-2}
threads=${3:-$(nproc)}
py=${YARNHOM_PYTHON:-/usr/bin/python3}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$build/tools/yarnhom" synth --preset paper -o "$tmp/d.h5" >/dev/null
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; threads $threads"
echo "load: $(uptime)"
time_recipe() {  # best of 3 wall times of train-all with recipe $1
  local best=1e9 s t
  for rep in 1 2 3; do
    s=$(date +%s.%N)
    "$build/tools/yarnhom" train-all "$tmp/d.h5" -o "$tmp/m.h5" -q --threads "$threads" --recipe "$1" >"$tmp/table_$1.txt"
    t=$(awk -v a="$s" -v b="$(date +%s.%N)" 'BEGIN{printf "%.2f", b - a}')
    echo "yarnhom train-all --recipe $1 run $rep: $t s" >&2
    best=$(awk -v a="$t" -v b="$best" 'BEGIN{print (a < b) ? a : b}')
  done
  echo "$best"
}
best_default=$(time_recipe default)
cat "$tmp/table_default.txt"
best=$(time_recipe paper)
"$py" "$here/reference/yarnhom_ref.py" train "$tmp/d.h5" --epochs "$epochs" --threads "$threads" | tee "$tmp/ref.txt"
ref=$(sed -n 's/.*extrapolated: \([0-9.]*\) s/\1/p' "$tmp/ref.txt")
echo "yarnhom default recipe best of 3: $best_default s (target 10 s)"
echo "yarnhom paper recipe best of 3: $best s; PyTorch reference (extrapolated): $ref s; ratio $(awk -v a="$ref" -v b="$best" 'BEGIN{printf "%.0f", a / b}')x"
