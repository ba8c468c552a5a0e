#!/usr/bin/env bash
# CI's build from cold, profiled: a fresh clone of HEAD, configured as scripts/build.sh does
# (Release, CUDA when nvcc is found, or YARNHOM_CUDA=ON|OFF), built with ccache off on CORES
# pinned cores (default 2, CI's machine) with -jCORES; every compile's CPU time (user + sys) and
# wall time go to OUT/compiles.log (a launcher wraps the compiler in /usr/bin/time), ninja's
# log to OUT/ninja_log. Then `ctest -jCORES` on the same cores, its per-test times in
# OUT/CTestCostData.txt. Prints the totals, the 25 dearest compiles and the CPU per target.
#   tools/bench/ci_build_profile.sh OUT [CORES] [--no-tests]
# CPU times barely depend on the machine's load; wall times do (the script prints the load).
set -euo pipefail
out=$(realpath -m "${1:?usage: ci_build_profile.sh OUT [CORES] [--no-tests]}")
cores=${2:-2}
tests=1
[ "${3:-}" = --no-tests ] && tests=0
repo=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"
src=$out/src
rm -rf "$src"
git clone -q "$repo" "$src"
cat > "$out/timeit.sh" <<EOF
#!/usr/bin/env bash
o=?; prev=
for a in "\$@"; do [ "\$prev" = -o ] && o=\$a; prev=\$a; done
exec /usr/bin/time -f "%U %S %e \$o" -a -o "$out/compiles.log" "\$@"
EOF
chmod +x "$out/timeit.sh"
rm -f "$out/compiles.log"
gen=()
command -v ninja >/dev/null && gen=(-G Ninja)
args=(-DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER_LAUNCHER="$out/timeit.sh" -DCMAKE_CUDA_COMPILER_LAUNCHER="$out/timeit.sh")
if [ "${YARNHOM_CUDA:-AUTO}" != OFF ] && ! command -v nvcc >/dev/null && [ -x /usr/local/cuda/bin/nvcc ]; then
  args+=(-DCMAKE_CUDA_COMPILER=/usr/local/cuda/bin/nvcc)
fi
args+=(-DYARNHOM_CUDA="${YARNHOM_CUDA:-AUTO}")
pin=(taskset -c "0-$((cores - 1))")
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
t0=$(date +%s)
CCACHE_DISABLE=1 cmake -S "$src" -B "$src/build" "${gen[@]}" "${args[@]}" > "$out/configure.log"
t1=$(date +%s)
CCACHE_DISABLE=1 "${pin[@]}" cmake --build "$src/build" -j"$cores" > "$out/build.log" 2>&1
t2=$(date +%s)
[ -f "$src/build/.ninja_log" ] && cp "$src/build/.ninja_log" "$out/ninja_log"
echo "configure $((t1 - t0)) s, build $((t2 - t1)) s on $cores cores (load after: $(cut -d' ' -f1-3 /proc/loadavg))"
awk '{c += $1 + $2; n++} END {printf "compiles: %d, %.0f s of CPU (%.0f s on %d cores)\n", n, c, c / '"$cores"', '"$cores"'}' "$out/compiles.log"
echo "dearest compiles (CPU s, wall s, object):"
awk '{printf "%8.1f %8.1f  %s\n", $1 + $2, $3, $4}' "$out/compiles.log" | sort -rn | head -25
echo "CPU per target (s, compiles):"
awk '{t = $4; sub(/\.dir\/.*/, "", t); sub(/.*CMakeFiles\//, "", t); c[t] += $1 + $2; n[t]++}
     END {for (t in c) printf "%8.1f %4d  %s\n", c[t], n[t], t}' "$out/compiles.log" | sort -rn
if [ "$tests" = 1 ]; then
  t3=$(date +%s)
  YARNHOM_NO_VIDEO=1 "${pin[@]}" ctest --test-dir "$src/build" -j"$cores" > "$out/ctest.log" 2>&1 || true
  echo "tests $(( $(date +%s) - t3 )) s: $(grep -E 'tests passed|tests failed' "$out/ctest.log" | tail -1)"
  cp "$src/build/Testing/Temporary/CTestCostData.txt" "$out/" 2>/dev/null || true
fi
