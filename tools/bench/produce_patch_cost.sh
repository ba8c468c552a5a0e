#!/bin/bash
# What a 2 x 2 patch RVE costs against one tile in `produce` (issue 34's goal: at most 8x the
# tile's CPU time): for each pattern, the same run at --tile 1,1 and --tile 2,2, one after the
# other, and the ratio of their CPU time in node solves (the `total` line's "s CPU", which a
# loaded machine inflates less than wall time; per term too). Figures: docs/benchmarks.md,
# "Patch RVEs".
#   tools/bench/produce_patch_cost.sh YARNHOM "PATTERNS" TERMS [PRESET] [THREADS] [OUTDIR]
# PATTERNS: names (the repository's ../shared/patterns/NAME.pyp when there, else the built-in) or .pyp
# paths; PRESET paper by default; THREADS 1 by default (CPU time is summed over threads).
# With DENSE=1 in the environment each run is repeated with every RVE factored densely
# (YARNHOM_RVE_DENSE_LIMIT=1000000: the factorization before issue 34), for a before/after.
# e.g. tools/bench/produce_patch_cost.sh build/tools/yarnhom \
#        "stockinette basket slip_stitch_honeycomb cartridge_belt_rib" 0,01,12 paper 16
set -u
Y=$(realpath "$1"); PATTERNS=$2; T=$3; PRESET=${4:-paper}; TH=${5:-1}; D=${6:-produce_patch_cost}
shared=$(realpath "$(dirname "$0")/../../..")/shared/patterns  # the repository's ../shared
mkdir -p "$D" && cd "$D"
targ=(--terms "$T"); [ "$T" = all ] && targ=()
cpu() { sed -n 's/^total .*(\([0-9.]*\) s CPU).*/\1/p' "$1"; }
run() {  # label pattern tile [env...]
  local label=$1 p=$2 tile=$3; shift 3
  local s; s=$(date +%s)
  env "$@" "$Y" produce "$p" --preset "$PRESET" "${targ[@]}" --tile "$tile" --threads "$TH" -o "$label.h5" > "$label.log" 2>&1
  echo "  $label: rc $?, $(( $(date +%s) - s )) s wall, $(grep -E '^total' "$label.log")" >&2
  grep -E '^[0-9]+ ' "$label.log" | awk -v l="$label" '{print "    " l " term " $1 ": " $6 " s CPU, mean iter " $4}' >&2
  cpu "$label.log"
}
for name in $PATTERNS; do
  p=$name
  [ -f "$p" ] || { [ -f "$shared/$name.pyp" ] && p="$shared/$name.pyp"; }
  [ -f "$p" ] && p=$(realpath "$p")
  b=$(basename "$name" .pyp)
  echo "$b ($PRESET, terms $T, $TH thread(s), load $(cut -d' ' -f1-3 /proc/loadavg)):"
  modes=("")
  [ "${DENSE:-0}" = 1 ] && modes+=("YARNHOM_RVE_DENSE_LIMIT=1000000")
  for m in "${modes[@]}"; do
    tag=""; envs=(); [ -n "$m" ] && { tag="_dense"; envs=("$m"); }
    c1=$(run "${b}_1x1$tag" "$p" 1,1 "${envs[@]}")
    c2=$(run "${b}_2x2$tag" "$p" 2,2 "${envs[@]}")
    echo "  ${b}${tag}: 1x1 ${c1} s CPU, 2x2 ${c2} s CPU, ratio $(awk -v a="$c1" -v b="$c2" 'BEGIN{if (a > 0) printf "%.1f", b / a; else print "-"}')x"
  done
done
