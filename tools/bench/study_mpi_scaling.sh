#!/bin/bash
# study table5 on MPI ranks (docs/produce.md, "The studies on a cluster"): the same study in one
# process (its stages on every core) and under `mpirun -np N --bind-to none` (each rank's stages
# on cores / N threads), one after another on an idle host, with the wall time, how many stages
# ran (each must run once) and table5.csv's md5 (equal in every run where the stages are
# deterministic at their thread counts: give --threads and the strips' --threads for that).
#   tools/bench/study_mpi_scaling.sh YARNHOM "1 4 8" [OUTDIR] -- PATTERN... [study table5 options]
# e.g. tools/bench/study_mpi_scaling.sh build/tools/yarnhom "1 4 8" t5 -- ../shared/patterns/basket.pyp \
#        ../shared/patterns/stockinette.pyp --preset quick --stretch 1.0:1.3:0.1
# Each run's output stays in OUTDIR/rN.log and its study in OUTDIR/rN/ (each rank's stage lines
# in OUTDIR/rN/logs/rank-R.log). As root, set OMPI_ALLOW_RUN_AS_ROOT=1
# OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; MPIRUN_ARGS adds mpirun options.
set -u
Y=$(realpath "$1"); RANKS=$2; D=${3:-study_mpi_scaling}
shift 3; [ "${1:-}" = -- ] && shift
args=()
for a in "$@"; do if [ -f "$a" ]; then args+=("$(realpath "$a")"); else args+=("$a"); fi; done
mkdir -p "$D" && cd "$D"
lscpu 2>/dev/null | grep -E '^(Model name|CPU\(s\)|Thread\(s\) per core|Socket\(s\))' | tr -s ' ' | paste -sd';' -
for n in $RANKS; do
  rm -rf r$n
  s=$(date +%s%N)
  if [ "$n" = 1 ]; then "$Y" study table5 "${args[@]}" -o r$n > r$n.log 2>&1
  else mpirun -np "$n" --bind-to none ${MPIRUN_ARGS:-} "$Y" study table5 "${args[@]}" -o r$n > r$n.log 2>&1; fi
  rc=$?
  stages=$(cat r$n.log r$n/logs/rank-*.log 2>/dev/null | grep -c ' running (')
  echo "$n rank(s): rc $rc, $(( ($(date +%s%N) - s) / 1000000 )) ms wall, $stages stages ran; table5.csv md5 $(md5sum < r$n/table5.csv | cut -c1-12)"
done
