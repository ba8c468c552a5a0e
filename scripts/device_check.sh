#!/usr/bin/env bash
# One call on the GPU machine: build, CUDA tests, kernel benchmarks, train-all timings (CUDA,
# CPU for reference, the PyTorch peer on the same GPU), and the CLI error paths. Logs go to
# $OUT (or ./device-out). Usage, from the repository root:
#   bash scripts/device_check.sh [build] [tests] [bench] [train] [torch] [faults]   (default: all)
# Needs .devdeps/ (../shared/tools/device-deps) on a machine without a package registry.
set -u -o pipefail
OUT=${OUT:-$PWD/device-out}
mkdir -p "$OUT"
steps=${*:-build tests bench train variants torch faults}
has() { [[ " $steps " == *" $1 "* ]]; }
[ -f .devdeps/env.sh ] && source .devdeps/env.sh
B=build-gpu
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,memory.total --format=csv | tee "$OUT/gpu.txt"
nproc >> "$OUT/gpu.txt"

if has build; then
  t0=$(date +%s)
  cmake -S . -B $B ${DEVDEPS_CMAKE_ARGS:-} -DYARNHOM_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 \
    -DCMAKE_BUILD_TYPE=Release > "$OUT/build.log" 2>&1 &&
    make -C $B -j"$(nproc)" yarnhom test_cuda bench_cuda >> "$OUT/build.log" 2>&1
  rc=$?
  echo "build rc=$rc in $(( $(date +%s) - t0 )) s"
  [ $rc -ne 0 ] && { tail -40 "$OUT/build.log"; exit 1; }
fi
Y=$B/tools/yarnhom

if has tests; then
  $B/tests/test_cuda --gtest_color=no 2>&1 | tee "$OUT/test_cuda.log" | grep -E "^\[  (PASSED|FAILED|SKIPPED) |FAILED|rel |worst|oom|launch:|Failure|Expected|actual|Which is" | head -60
fi

if has benchcuda; then
  $B/tools/bench_cuda --benchmark_filter=BM_Cuda --benchmark_out="$OUT/bench_cuda.json" --benchmark_out_format=json \
    > "$OUT/bench_cuda.log" 2>&1
  echo "bench rc=$?"
  grep -E "^GPU|BM_" "$OUT/bench_cuda.log" | sed -E 's/ +/ /g' | cut -c1-170
fi

if has bench; then
  $B/tools/bench_cuda --benchmark_out="$OUT/bench_cuda.json" --benchmark_out_format=json \
    > "$OUT/bench_cuda.log" 2>&1
  echo "bench rc=$?"
  grep -E "^GPU|BM_" "$OUT/bench_cuda.log" | sed -E 's/ +/ /g' | cut -c1-170
fi

if has train || has torch || has faults || has sanitize || has variants; then
  $Y synth --preset paper -o /tmp/paper.h5 > /dev/null && $Y synth --preset quick -o /tmp/quick.h5 > /dev/null
fi

if has train; then
  for r in 1 2 3; do
    /usr/bin/time -f "cuda train-all paper run $r: %e s wall (process)" \
      $Y train-all /tmp/paper.h5 -o /tmp/model_cuda_$r.h5 --backend cuda -q > "$OUT/train_cuda_$r.log" 2>&1
    echo "rc=$?"; tail -1 "$OUT/train_cuda_$r.log"; grep "total wall" "$OUT/train_cuda_$r.log"
  done
  cat "$OUT/train_cuda_1.log" | head -20
  # HDF5 stores object times, so compare the weights and histories, not the bytes.
  python3 - <<'PY'
import h5py, numpy as np
a, b = h5py.File("/tmp/model_cuda_1.h5"), h5py.File("/tmp/model_cuda_2.h5")
same = []
def walk(name, obj):
    if isinstance(obj, h5py.Dataset):
        same.append(np.array_equal(obj[()], b[name][()]))
a.visititems(walk)
print(f"paper models of runs 1 and 2: {sum(same)} of {len(same)} datasets bit-identical")
PY
  /usr/bin/time -f "cpu train-all paper 50 epochs: %e s" \
    $Y train-all /tmp/paper.h5 -o /tmp/model_cpu50.h5 --backend cpu --epochs 50 -q > "$OUT/train_cpu50.log" 2>&1
  grep "total wall" "$OUT/train_cpu50.log"; tail -1 "$OUT/train_cpu50.log"
  cp /tmp/model_cuda_1.h5 "$OUT/model_cuda_paper.h5"
fi

if has variants; then
  for th in 256 512; do
    for cb in 1 2 4 8; do
      YARNHOM_CUDA_THREADS=$th YARNHOM_CUDA_CLUSTER=$cb /usr/bin/time -f "%e s process" $Y train-all /tmp/paper.h5 \
        -o /tmp/v.h5 --backend cuda -q > /tmp/v.log 2>&1
      echo "threads $th cluster $cb: $(grep 'total wall' /tmp/v.log | cut -c1-26) $(tail -1 /tmp/v.log)"
    done
  done
  $Y train-all /tmp/paper.h5 -o /tmp/v.h5 --backend cuda -q --terms 0,1,2,3,5 > /tmp/v.log 2>&1
  echo "1D terms only: $(grep 'total wall' /tmp/v.log)"
  $Y train-all /tmp/paper.h5 -o /tmp/v.h5 --backend cuda -q --terms 01,02,03,05,12,13,15,23,25 > /tmp/v.log 2>&1
  echo "2D terms only: $(grep 'total wall' /tmp/v.log)"
  /usr/bin/time -f "cpu train-all paper 500 epochs: %e s" \
    $Y train-all /tmp/paper.h5 -o /tmp/model_cpu.h5 --backend cpu -q > "$OUT/train_cpu500.log" 2>&1
  grep "total wall" "$OUT/train_cpu500.log"; tail -1 "$OUT/train_cpu500.log"
fi

if has torch; then
  PYTHONUNBUFFERED=1 timeout 300 python3 scripts/reference/yarnhom_ref.py train /tmp/paper.h5 --epochs 3 --device cuda \
    2>&1 | tee "$OUT/torch_peer.log" | tail -16
fi

if has sanitize; then
  # Races, barrier misuse and bad accesses in the twins and in the fused epoch kernel.
  for tool in memcheck racecheck synccheck; do
    compute-sanitizer --tool $tool --error-exitcode 9 $B/tests/test_cuda --gtest_filter='*FusedLossGradMatchesCpu*:*Backward*:*CudaMma*' \
      > "$OUT/sanitize_tests_$tool.log" 2>&1
    echo "compute-sanitizer $tool, kernel tests: exit $? $(grep -h 'ERROR SUMMARY' "$OUT/sanitize_tests_$tool.log" | tail -1)"
    compute-sanitizer --tool $tool --error-exitcode 9 $Y train-all /tmp/quick.h5 -o /tmp/san.h5 --backend cuda --epochs 2 -q \
      > "$OUT/sanitize_train_$tool.log" 2>&1
    echo "compute-sanitizer $tool, train-all quick 2 epochs: exit $? $(grep -h 'ERROR SUMMARY' "$OUT/sanitize_train_$tool.log" | tail -1)"
  done
fi

if has profile; then
  # The fused loss + gradient at batch 2^20 (the tensor-core path, d = 1 and 2), one launch each:
  # the sections, then raw counters (a separate call: a metric this ncu lacks fails only that one).
  for d in 1 2; do
    args=(--clock-control none --kernel-name regex:loss_grad_kernel --launch-skip 3 --launch-count 1)
    bench=($B/tools/bench_cuda --benchmark_filter="BM_Cuda_FusedFwdBwd/$d/1048576/0/0/0")
    ncu "${args[@]}" --section SpeedOfLight --section ComputeWorkloadAnalysis --section WarpStateStats \
      --section InstructionStats --section MemoryWorkloadAnalysis --section Occupancy --section LaunchStats \
      "${bench[@]}" > "$OUT/ncu_loss_grad_d$d.log" 2>&1
    echo "ncu d=$d rc=$?"
    grep -E "Duration|Throughput|Pipe|Issue|Stall|Warp Cycles|Achieved Occupancy|Theoretical Occupancy|Bank|Executed Ipc|Registers|Block Limit" "$OUT/ncu_loss_grad_d$d.log" | head -40
    ncu "${args[@]}" --metrics smsp__inst_executed.sum,sm__pipe_tensor_cycles_active.avg.pct_of_peak_sustained_active,sm__inst_executed_pipe_lsu.avg.pct_of_peak_sustained_active,l1tex__data_pipe_lsu_wavefronts_mem_shared.sum,l1tex__data_bank_conflicts_pipe_lsu_mem_shared.sum,smsp__warp_issue_stalled_short_scoreboard_per_warp_active.pct,smsp__warp_issue_stalled_mio_throttle_per_warp_active.pct,smsp__warp_issue_stalled_math_pipe_throttle_per_warp_active.pct,smsp__warp_issue_stalled_wait_per_warp_active.pct,smsp__warp_issue_stalled_long_scoreboard_per_warp_active.pct,smsp__warp_issue_stalled_barrier_per_warp_active.pct,smsp__warp_issue_stalled_not_selected_per_warp_active.pct,smsp__warp_issue_stalled_selected_per_warp_active.pct,smsp__warp_issue_stalled_dispatch_stall_per_warp_active.pct \
      "${bench[@]}" > "$OUT/ncu_metrics_d$d.log" 2>&1
    echo "ncu metrics d=$d rc=$?"
    grep -E "smsp__|sm__|l1tex__|ERROR|error" "$OUT/ncu_metrics_d$d.log" | head -20
  done
fi

if has faults; then
  for f in oom launch; do
    rm -f /tmp/fault.h5
    YARNHOM_CUDA_FAULT=$f $Y train-all /tmp/quick.h5 -o /tmp/fault.h5 --backend cuda --epochs 3 -q > "$OUT/fault_$f.log" 2>&1
    echo "fault $f: exit $? ; model file $( [ -e /tmp/fault.h5 ] && echo WRITTEN || echo absent ); $(grep -h error "$OUT/fault_$f.log" | head -2)"
  done
  CUDA_VISIBLE_DEVICES= $Y train-all /tmp/quick.h5 -o /tmp/fault.h5 --backend cuda --epochs 3 -q > "$OUT/fault_nogpu.log" 2>&1
  echo "no GPU visible: exit $? ; model file $( [ -e /tmp/fault.h5 ] && echo WRITTEN || echo absent ); $(grep -h error "$OUT/fault_nogpu.log" | head -2)"
  CUDA_VISIBLE_DEVICES= $B/tests/test_cuda --gtest_color=no 2>&1 | tail -3
fi
