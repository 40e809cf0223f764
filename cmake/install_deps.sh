#!/usr/bin/env bash
# Installs the Debian packages sextant needs to build, test and benchmark, if any are missing.
set -euo pipefail
# libmrpt-dev: rawlogs, 3D scenes, CConfigFile; mrpt-common: the kf-slam demo rawlogs; libzip-dev: .npz files;
# libopencv-dev: the visual front-end (sextant::vision); python3-matplotlib: --plots; clang: run.sh's
# compiler (docs/build_times.md), g++ the benchmarks' and the thread-sanitizer build's; libopenmpi-dev,
# openmpi-bin: mpirun over a Monte Carlo study's seeds (docs/monte_carlo_clusters.md); libopenblas-pthread-dev:
# SEIF's large dense Cholesky (core/dense_cholesky.hpp) and the BLAS under CHOLMOD and Ceres (not the serial
# OpenBLAS: Debian builds it without locking, and two threads calling it at once get wrong results)
packages=(cmake make g++ clang libeigen3-dev libboost-dev libgtest-dev libbenchmark-dev libcli11-dev libsuitesparse-dev libceres-dev
          libopenblas-pthread-dev libmrpt-dev mrpt-common libzip-dev libopencv-dev python3-matplotlib
          libopenmpi-dev openmpi-bin "$@")  # "$@": extra packages to install
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "sextant: installing missing Debian packages: ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "sextant: need root or sudo to install ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
