#!/usr/bin/env bash
# The README's first command: installs what is missing, builds, and runs the main job on an
# embedded default: the whole pipeline on the built-in (generated) stockinette pattern at the
# quick preset -- yarn RVE data, 14 networks trained with the paper's recipe, Hermite tables,
# metrics and plots -- in a minute or so on 2 cores. Outputs land in runs/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
./build/tools/yarnhom pipeline stockinette -o runs/demo --preset quick
./build/tools/yarnhom eval runs/demo/model.h5 --term 02 --at 0.1,0.2 --at 0.5,-0.1
