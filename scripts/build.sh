#!/usr/bin/env bash
# Configures and builds yarnhom in ./build (Release; YARNHOM_BUILD_DIR=DIR for another folder).
# The CUDA backend is compiled when nvcc is found (on PATH or in /usr/local/cuda);
# YARNHOM_CUDA=OFF (or ON) in the environment decides. Further arguments go to cmake.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${YARNHOM_BUILD_DIR:-build}
args=(-DCMAKE_BUILD_TYPE=Release)
cuda=${YARNHOM_CUDA:-AUTO}
if [ "$cuda" != OFF ] && ! command -v nvcc >/dev/null && [ -x /usr/local/cuda/bin/nvcc ]; then
  args+=(-DCMAKE_CUDA_COMPILER=/usr/local/cuda/bin/nvcc)
fi
args+=(-DYARNHOM_CUDA="$cuda")
cmake -S . -B "$dir" "${args[@]}" "$@" >/dev/null
cmake --build "$dir" -j"$(nproc)"
