#!/bin/bash
# produce on MPI ranks: the same paper-preset run on 1 process (1 thread) and on N ranks, one after
# another on an idle host, with the wall time, the sum of the node solves' times, where the ranks'
# time went (the summary's `ranks` line: busy share of each pass, jobs solved ahead) and each
# dataset's md5 (they must all be equal). Figures: docs/benchmarks.md, "On MPI ranks".
#   tools/bench/produce_mpi_scaling.sh YARNHOM PATTERN TERMS "1 4 16 64" [OUTDIR]
# e.g. tools/bench/produce_mpi_scaling.sh build/tools/yarnhom ../shared/patterns/stockinette.pyp \
#        0,1,2,3,5,01,02,12 "1 16 64"
# Each run's whole log (with one line per rank) stays in OUTDIR/rN.log. As root, set
# OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; MPIRUN_ARGS adds mpirun options.
set -u
Y=$(realpath "$1"); P=$(realpath "$2"); T=$3; RANKS=$4; D=${5:-produce_mpi_scaling}
mkdir -p "$D" && cd "$D"
targ=(--terms "$T"); [ "$T" = all ] && targ=()
# The host: cores, hardware threads per core, sockets (a rank per hardware thread shares a core).
lscpu 2>/dev/null | grep -E '^(Model name|CPU\(s\)|Thread\(s\) per core|Core\(s\) per socket|Socket\(s\)|CPU max MHz)' |
  tr -s ' ' | paste -sd';' -
for n in $RANKS; do
  s=$(date +%s%N)
  if [ "$n" = 1 ]; then "$Y" produce "$P" --preset paper "${targ[@]}" -o r$n.h5 --threads 1 > r$n.log 2>&1
  else mpirun -np "$n" --bind-to core ${MPIRUN_ARGS:-} "$Y" produce "$P" --preset paper "${targ[@]}" -o r$n.h5 > r$n.log 2>&1; fi
  rc=$?
  echo "$n rank(s): rc $rc, $(( ($(date +%s%N) - s) / 1000000 )) ms wall; $(grep -E '^total' r$n.log); md5 $(md5sum < r$n.h5 | cut -c1-12)"
  grep -E '^ranks' r$n.log
done
