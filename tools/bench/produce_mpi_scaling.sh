#!/bin/bash
# produce on MPI ranks: the same paper-preset run on 1 process (1 thread) and on N ranks, one after
# another on an idle host, with the wall time, the sum of the node solves' times and each
# dataset's md5 (they must all be equal). Figures: docs/benchmarks.md, "On MPI ranks".
#   tools/bench/produce_mpi_scaling.sh YARNHOM PATTERN TERMS "1 4 16 64" [OUTDIR]
# e.g. tools/bench/produce_mpi_scaling.sh build/tools/yarnhom ../shared/patterns/stockinette.pyp \
#        0,1,2,3,5,01,02,12 "1 4 16 64"
set -u
Y=$(realpath "$1"); P=$(realpath "$2"); T=$3; RANKS=$4; D=${5:-produce_mpi_scaling}
mkdir -p "$D" && cd "$D"
targ=(--terms "$T"); [ "$T" = all ] && targ=()
for n in $RANKS; do
  s=$(date +%s%N)
  if [ "$n" = 1 ]; then "$Y" produce "$P" --preset paper "${targ[@]}" -o r$n.h5 --threads 1 > r$n.log 2>&1
  else mpirun -np "$n" --bind-to core "$Y" produce "$P" --preset paper "${targ[@]}" -o r$n.h5 > r$n.log 2>&1; fi
  rc=$?
  echo "$n rank(s): rc $rc, $(( ($(date +%s%N) - s) / 1000000 )) ms wall; $(grep -E '^total' r$n.log); md5 $(md5sum < r$n.h5 | cut -c1-12)"
done
