#!/usr/bin/env bash
# sextant's entry point. Installs missing Debian packages, configures and builds (Release), then:
#   ./run.sh            the main job: sextant-run, every back-end on the ship simulation and MRPT's
#                       kf-slam demo rawlogs, comparison table
#   ./run.sh test       the test suite (ctest; long statistical tests labelled 'slow' are left out)
#   ./run.sh bench      the Google Benchmark programs
# Extra arguments after the mode go to the program it runs.
set -euo pipefail
cd "$(dirname "$0")"
mode=${1:-main}
[ $# -gt 0 ] && shift
bash cmake/install_deps.sh
build=${SEXTANT_BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j"$jobs"
case "$mode" in
  main) exec "$build/examples/sextant-run" "$@" ;;
  test) cd "$build" && exec ctest --output-on-failure -j"$jobs" -LE slow "$@" ;;
  bench) for b in "$build"/benchmarks/*_benchmark; do "$b" "$@"; done ;;
  *) echo "usage: ./run.sh [main|test|bench] [args...]" >&2; exit 2 ;;
esac
