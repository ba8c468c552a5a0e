#!/bin/bash
# The 2 x 2 patch datasets at the paper preset (issue 34: beside supplement Table 2's Size-2
# column), produced on MPI ranks in calls of bounded length: each call works through the patterns
# in order for at most BUDGET seconds and stops (mpirun ended by `timeout`; the checkpoint keeps
# every finished node), the next call with the same STATEDIR resumes where it stopped. Prints
# per pattern this call's wall time, the total over all calls so far, and the summary once done.
#   tools/bench/produce_patch_paper.sh YARNHOM "PATTERNS" NP BUDGET [STATEDIR] [TERMS]
# PATTERNS: .pyp paths or names (the repository's ../shared/patterns/NAME.pyp); NP: mpirun -np
# (1: one process on all cores' threads); BUDGET: seconds for this call; STATEDIR (default
# build/produce_patch_paper: inside the git-ignored build folder, so it stays between calls on a
# machine that keeps build outputs) holds NAME_2x2.h5, its checkpoint NAME_2x2.h5.partial, the
# logs and the wall time so far; TERMS: all by default.
# On the 64-core GPU host (a build with -DYARNHOM_MPI=ON; as root):
#   OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
#   OMPI_MCA_btl_vader_single_copy_mechanism=none MPIRUN_ARGS=--oversubscribe \
#   tools/bench/produce_patch_paper.sh build/tools/yarnhom "basket stockinette slip_stitch_honeycomb" 64 510
# repeated (each call within 9 minutes) until it prints "all done".
set -u
Y=$(realpath "$1"); PATTERNS=$2; NP=$3; BUDGET=$4; D=${5:-build/produce_patch_paper}; T=${6:-all}
shared=$(realpath "$(dirname "$0")/../../..")/shared/patterns  # the repository's ../shared
mkdir -p "$D" && D=$(realpath "$D")
targ=(--terms "$T"); [ "$T" = all ] && targ=()
start=$(date +%s)
echo "host: $(nproc) CPUs, $(lscpu 2>/dev/null | sed -n 's/^Model name: *//p'); load $(cut -d' ' -f1-3 /proc/loadavg); np $NP, budget $BUDGET s"
all=1
for name in $PATTERNS; do
  p=$name
  [ -f "$p" ] || { [ -f "$shared/$name.pyp" ] && p="$shared/$name.pyp"; }
  b=$(basename "$name" .pyp)
  out=$D/${b}_2x2.h5
  if [ -f "$D/$b.done" ]; then
    echo "$b: done earlier, $(cat "$D/$b.wall" 2>/dev/null || echo '?') s wall in all; $(grep -E '^total' "$D/$b.log" | tail -1)"
    continue
  fi
  left=$(( BUDGET - ($(date +%s) - start) ))
  if [ "$left" -lt 20 ]; then all=0; echo "$b: not started (budget spent)"; continue; fi
  s=$(date +%s%N)
  if [ "$NP" = 1 ]; then
    timeout -k 10 "$left" "$Y" produce "$p" --preset paper "${targ[@]}" --tile 2,2 --threads "$(nproc)" -o "$out" >> "$D/$b.log" 2>&1
  else
    timeout -k 10 "$left" mpirun -np "$NP" --bind-to core ${MPIRUN_ARGS:-} "$Y" produce "$p" --preset paper "${targ[@]}" \
      --tile 2,2 -o "$out" >> "$D/$b.log" 2>&1
  fi
  rc=$?
  ms=$(( ($(date +%s%N) - s) / 1000000 ))
  prev=$(cat "$D/$b.wall" 2>/dev/null || echo 0)
  tot=$(awk -v a="$prev" -v b="$ms" 'BEGIN{printf "%.1f", a + b / 1000}')
  echo "$tot" > "$D/$b.wall"
  if [ "$rc" = 0 ] && [ -f "$out" ]; then
    touch "$D/$b.done"
    echo "$b: done, rc $rc, this call $(( ms / 1000 )) s, $tot s wall in all; $(grep -E '^total' "$D/$b.log" | tail -1); md5 $(md5sum < "$out" | cut -c1-12)"
    grep -E '^(ranks|[0-9]+ +[0-9]+ )' "$D/$b.log" | tail -25
  else
    all=0
    echo "$b: stopped (rc $rc) after $(( ms / 1000 )) s this call, $tot s wall in all; $(grep -c . "$D/$b.log") log lines, last: $(tail -c 300 "$D/$b.log" | tr '\r' '\n' | tail -1)"
  fi
done
[ "$all" = 1 ] && echo "all done" || echo "call again to resume"
