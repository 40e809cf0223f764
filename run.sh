#!/usr/bin/env bash
# sextant's entry point. Installs missing Debian packages, configures and builds (Release) what the
# mode runs, then:
#   ./run.sh            the main job: sextant-run, every back-end on the ship simulation and MRPT's
#                       kf-slam demo rawlogs, comparison table
#   ./run.sh test       the test suite (ctest; tests labelled 'slow' are left out: ./run.sh test-slow runs them)
#   ./run.sh bench      the Google Benchmark programs
# Extra arguments after the mode go to the program it runs.
set -euo pipefail
cd "$(dirname "$0")"
mode=${1:-main}
[ $# -gt 0 ] && shift
bash cmake/install_deps.sh
build=${SEXTANT_BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
configure() { cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DSEXTANT_REQUIRE_ALL_DEPENDENCIES=ON "$@" >/dev/null; }
case "$mode" in
  main)
    configure -DSEXTANT_BUILD_TESTS=OFF -DSEXTANT_BUILD_BENCHMARKS=OFF
    targets=(sextant-run)
    case " $* " in *globe*) targets+=(sextant-globe) ;; esac  # --dataset globe hands over to sextant-globe
    cmake --build "$build" -j"$jobs" --target "${targets[@]}"
    exec "$build/examples/sextant-run" "$@" ;;
  test|test-slow)
    configure -DSEXTANT_BUILD_TESTS=ON
    cmake --build "$build" -j"$jobs" --target sextant_tests
    label=(-LE slow)
    [ "$mode" = test-slow ] && label=(-L slow)
    cd "$build" && exec ctest --output-on-failure -j"$jobs" "${label[@]}" "$@" ;;
  bench)
    configure -DSEXTANT_BUILD_BENCHMARKS=ON
    cmake --build "$build" -j"$jobs" --target sextant_benchmarks
    for b in "$build"/benchmarks/*_benchmark; do "$b" "$@"; done ;;
  *) echo "usage: ./run.sh [main|test|test-slow|bench] [args...]" >&2; exit 2 ;;
esac
