#!/usr/bin/env bash
# The README's first command: installs what is missing, builds, and runs the main job on an
# embedded default: a synthetic dataset (the paper's sampling density) and train-all with the
# paper's recipe (14 networks, 500 epochs), then evaluates one term.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install-deps.sh
bash tools/build.sh
mkdir -p runs/demo
./build/tools/yarnhom synth --preset paper -o runs/demo/dataset.h5
./build/tools/yarnhom train-all runs/demo/dataset.h5 -o runs/demo/model.h5
./build/tools/yarnhom eval runs/demo/model.h5 --term 02 --at 0.1,0.2 --at 0.5,-0.1
echo "demo: dataset and model in runs/demo/"
