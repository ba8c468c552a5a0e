#!/usr/bin/env bash
# The train-all benchmark of docs/benchmarks.md: `yarnhom train-all` with the paper's recipe
# (14 networks, 500 epochs) on `synth --preset paper`, against the PyTorch reference of the
# same recipe on the same machine in the same run (EPOCHS epochs per network, extrapolated to
# 500). Usage: bash tools/bench_train_all.sh [BUILD_DIR] [EPOCHS] [THREADS]
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
best=1e9
for rep in 1 2 3; do
  s=$(date +%s.%N)
  "$build/tools/yarnhom" train-all "$tmp/d.h5" -o "$tmp/m.h5" -q --threads "$threads" >"$tmp/table.txt"
  t=$(awk -v a="$s" -v b="$(date +%s.%N)" 'BEGIN{printf "%.2f", b - a}')
  echo "yarnhom train-all run $rep: $t s"
  best=$(awk -v a="$t" -v b="$best" 'BEGIN{print (a < b) ? a : b}')
done
cat "$tmp/table.txt"
"$py" "$here/reference/yarnhom_ref.py" train "$tmp/d.h5" --epochs "$epochs" --threads "$threads" | tee "$tmp/ref.txt"
ref=$(sed -n 's/.*extrapolated: \([0-9.]*\) s/\1/p' "$tmp/ref.txt")
echo "yarnhom best of 3: $best s; PyTorch reference (extrapolated): $ref s; ratio $(awk -v a="$ref" -v b="$best" 'BEGIN{printf "%.0f", a / b}')x"
