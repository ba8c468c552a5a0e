#!/usr/bin/env bash
# Installs, from Debian 12's packages, what yarnhom needs to build, test and plot, skipping
# what is already there. Runs apt-get through sudo when not root.
set -euo pipefail
pkgs=(build-essential cmake pkg-config libeigen3-dev libhdf5-dev libcli11-dev libgtest-dev
      libgmock-dev libbenchmark-dev nlohmann-json3-dev libsuitesparse-dev python3 python3-numpy python3-h5py python3-matplotlib
      libopenblas0-pthread ccache)
# libopenblas0-pthread becomes the system's libblas.so.3 / liblapack.so.3 (Debian alternatives):
# CHOLMOD's supernodal factorization, which the simulators' Newton solves spend most of their
# time in, runs ~5x faster on it than on the reference BLAS (docs/benchmarks.md). No rebuild
# needed: the programs link libblas.so.3, whichever provides it.
# ccache is optional: .ci/run builds twice (with and without the CUDA backend) through it.
# PyTorch is only the reference the tests compare against (skipped without it); set
# YARNHOM_NO_TORCH=1 to leave it out.
[ "${YARNHOM_NO_TORCH:-0}" = 1 ] || pkgs+=(python3-torch)
# pybind11-dev (headers only) and python3-dev: the Python module (python/, built when found).
pkgs+=(pybind11-dev python3-dev)
# ffmpeg: sim's video of every run (OUT/sim.mp4; without it sim says so in one line and writes
# the rest). About 27 MB to download, 68 MB installed on Debian 12; YARNHOM_NO_FFMPEG=1 leaves it out.
[ "${YARNHOM_NO_FFMPEG:-0}" = 1 ] || pkgs+=(ffmpeg)
# Open MPI: `mpirun -np N yarnhom produce` on several processes or machines (docs/produce.md,
# "On a cluster"); the build finds it (YARNHOM_MPI=AUTO). YARNHOM_NO_MPI=1 leaves it out.
[ "${YARNHOM_NO_MPI:-0}" = 1 ] || pkgs+=(libopenmpi-dev openmpi-bin)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: everything is installed"
  exit 0
fi
sudo=""
[ "$(id -u)" -eq 0 ] || sudo=sudo
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
