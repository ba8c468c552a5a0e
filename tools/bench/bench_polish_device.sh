#!/usr/bin/env bash
# The polish's figures on the GPU host, in one call (docs/benchmarks.md, "The polish"): build,
# the CUDA polish tests, train-all on `synth --preset paper` with the default recipe on the GPU
# (twice: bit-identical?), the same with the polish left to the CPU (YARNHOM_CUDA_POLISH=cpu,
# the old behaviour), the paper's recipe on the GPU, the CPU default and paper recipes on 2
# pinned cores, bench_polish, the training step's kernels on one pinned core (bench_kernels
# BM_training_step: the general kernel and the epochs' fused kernel), and the PyTorch reference of
# the paper's recipe on the same GPU. The cpu step alternates the epochs' fused kernel with the
# general one (YARNHOM_CPU_EPOCH_KERNEL=general, the behaviour before it), two runs of each; the
# train and cpu steps also alternate the 2D polishes' L-BFGS memory 10 (before session 47) and 30.
# From the repository root, on the device machine:
#   bash tools/bench/bench_polish_device.sh [build] [tests] [train] [cpu] [bench] [kernels] [torch]   (default: all)
set -u -o pipefail
OUT=${OUT:-$PWD/device-out}
mkdir -p "$OUT"
steps=${*:-build tests train cpu bench kernels torch}
has() { [[ " $steps " == *" $1 "* ]]; }
[ -f .devdeps/env.sh ] && source .devdeps/env.sh
B=${B:-/tmp/build-gpu}
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,memory.total --format=csv,noheader | tee "$OUT/gpu.txt"
lscpu | grep -E "Model name|^CPU\(s\)" | tee -a "$OUT/gpu.txt"

if has build; then
  t0=$(date +%s)
  cmake -S . -B $B ${DEVDEPS_CMAKE_ARGS:-} -DYARNHOM_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 \
    -DCMAKE_BUILD_TYPE=Release > "$OUT/build.log" 2>&1 &&
    make -C $B -j"$(nproc)" yarnhom test_cuda bench_polish bench_kernels >> "$OUT/build.log" 2>&1
  rc=$?
  echo "build rc=$rc in $(( $(date +%s) - t0 )) s"
  [ $rc -ne 0 ] && { grep -E "error|Error" "$OUT/build.log" | head -30; tail -20 "$OUT/build.log"; exit 1; }
fi
Y=$B/tools/yarnhom
$Y synth --preset paper -o /tmp/paper.h5 > /dev/null

if has tests; then
  timeout 240 $B/tests/test_cuda --gtest_color=no --gtest_filter='CudaPolish.*' 2>&1 | tee "$OUT/test_cuda_polish.log" |
    grep -vE "^\[ RUN|^\[       OK" | tail -50
fi

run() {  # label, then the command; prints the process wall time and the trainer's line
  local label=$1; shift
  /usr/bin/time -f "%e" -o /tmp/t.txt "$@" > /tmp/r.log 2>&1
  echo "$label: rc=$? process $(cat /tmp/t.txt) s, $(grep 'total wall' /tmp/r.log | cut -d' ' -f1-4)"
}

if has train; then
  for r in 1 2 3; do run "cuda default run $r" $Y train-all /tmp/paper.h5 -o /tmp/m_cuda_$r.h5 --backend cuda -q; done
  cp /tmp/r.log "$OUT/train_cuda_default.log"
  head -17 /tmp/r.log
  YARNHOM_CUDA_POLISH_PROFILE=1 $Y train-all /tmp/paper.h5 -o /tmp/m_prof.h5 --backend cuda -q 2>&1 |
    grep -E "polish on the GPU|kcycles" | tee "$OUT/polish_profile.txt"
  python3 - <<'PY'
import h5py, numpy as np
a, b = h5py.File("/tmp/m_cuda_1.h5"), h5py.File("/tmp/m_cuda_2.h5")
same = []
def walk(name, obj):
    if isinstance(obj, h5py.Dataset):
        same.append(np.array_equal(obj[()], b[name][()]))
a.visititems(walk)
print(f"default-recipe models of runs 1 and 2: {sum(same)} of {len(same)} datasets bit-identical")
PY
  for r in 1 2; do
    YARNHOM_CUDA_POLISH=cpu run "cuda default, polish on the CPU (16 threads), run $r" \
      $Y train-all /tmp/paper.h5 -o /tmp/m_cpupol.h5 --backend cuda -q
  done
  head -17 /tmp/r.log | cut -c1-100
  for r in 1 2; do run "cuda paper recipe run $r" $Y train-all /tmp/paper.h5 -o /tmp/m_paper.h5 --backend cuda --recipe paper -q; done
  # The 2D polishes' L-BFGS memory: 30 (the default since session 47) against the 10 before.
  for r in 1 2; do
    run "cuda default, 2D memory 10 (before), run $r" $Y train-all /tmp/paper.h5 -o /tmp/m_m10.h5 --backend cuda -q --polish-memory-2d 10
    run "cuda default, 2D memory 30 (default), run $r" $Y train-all /tmp/paper.h5 -o /tmp/m_m30.h5 --backend cuda -q
  done
  YARNHOM_CUDA_POLISH_PROFILE=1 $Y train-all /tmp/paper.h5 -o /tmp/m_prof10.h5 --backend cuda -q --polish-memory-2d 10 2>&1 |
    grep -E "polish on the GPU|kcycles" | sed 's/^/memory 10: /' | tee "$OUT/polish_profile_m10.txt"
  for c in 1 2 4 8; do
    YARNHOM_CUDA_POLISH_CLUSTER=$c run "cuda default, polish cluster $c" $Y train-all /tmp/paper.h5 -o /tmp/m_c.h5 --backend cuda -q
  done
fi

if has cpu; then
  for r in 1 2; do
    for k in fused general; do
      YARNHOM_CPU_EPOCH_KERNEL=$k run "cpu default, 2 threads pinned (taskset 0,1), epoch kernel $k, run $r" \
        taskset -c 0,1 $Y train-all /tmp/paper.h5 -o /tmp/m_cpu_$k.h5 --threads 2 -q
      cp /tmp/r.log "$OUT/train_cpu_default_$k.log"
      grep -c FAILS /tmp/r.log | sed 's/^/  failing terms: /'
    done
  done
  for r in 1 2; do
    for m in 10 30; do
      run "cpu default, 2 threads pinned (taskset 0,1), 2D memory $m, run $r" \
        taskset -c 0,1 $Y train-all /tmp/paper.h5 -o /tmp/m_cpu_m$m.h5 --threads 2 -q --polish-memory-2d $m
      grep -c FAILS /tmp/r.log | sed 's/^/  failing terms: /'
    done
  done
  for r in 1 2; do
    for k in fused general; do
      YARNHOM_CPU_EPOCH_KERNEL=$k run "cpu paper recipe, 2 threads pinned, epoch kernel $k, run $r" \
        taskset -c 0,1 $Y train-all /tmp/paper.h5 -o /tmp/m_cpup.h5 --threads 2 --recipe paper -q
    done
  done
fi

if has kernels; then
  taskset -c 2 $B/tools/bench_kernels --benchmark_filter=BM_training_step --benchmark_min_time=0.3 2>&1 |
    tee "$OUT/bench_kernels_step.log" | grep -E "^BM_" | sed -E 's/ +/ /g'
fi

if has bench; then
  taskset -c 2 $B/tools/bench_polish --benchmark_min_time=0.3 --benchmark_out="$OUT/bench_polish.json" \
    --benchmark_out_format=json > "$OUT/bench_polish.log" 2>&1
  echo "bench rc=$?"
  grep -E "^BM_" "$OUT/bench_polish.log" | sed -E 's/ +/ /g' | cut -c1-170
fi

if has torch; then
  PYTHONUNBUFFERED=1 timeout 240 python3 scripts/reference/yarnhom_ref.py train /tmp/paper.h5 --epochs 3 --device cuda \
    2>&1 | tee "$OUT/torch_peer.log" | tail -6
fi
