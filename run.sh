#!/usr/bin/env bash
# sextant's entry point. Installs missing Debian packages, configures and builds (Release) what the
# mode runs, then:
#   ./run.sh            the main job: sextant-run, every back-end on the ship simulation and MRPT's
#                       kf-slam demo rawlogs, comparison table
#   ./run.sh test       the test suite (ctest; tests labelled 'slow' are left out: ./run.sh test-slow runs them)
#   ./run.sh test-sanitize  the back-end, reader and model tests built by clang with AddressSanitizer +
#                       UndefinedBehaviorSanitizer (back-ends -O1, most test units -O0, any report stops
#                       the test) in build-sanitize/
#   ./run.sh test-tsan  the thread-safety tests (concurrent reads, Monte Carlo threads) under ThreadSanitizer
#   ./run.sh fuzz [s]   every reader's libFuzzer target (clang, ASan + UBSan) for s seconds each
#                       (default 60) in build-fuzz/, seeds from ../shared/data and MRPT's demo files
#   ./run.sh bench      the Google Benchmark programs
# Extra arguments after the mode go to the program it runs.
set -euo pipefail
cd "$(dirname "$0")"
mode=${1:-main}
[ $# -gt 0 ] && shift
bash cmake/install_deps.sh
source cmake/openblas_coretype.sh  # OpenBLAS's vector kernels on a CPU it does not know
build=${SEXTANT_BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
# clang++ compiles sextant 2.2x faster than g++ and the outputs are bit-identical (docs/build_times.md);
# SEXTANT_CXX=g++ chooses another compiler for a new build directory.
cxx=${SEXTANT_CXX:-clang++}
configure() {
  local compiler=()
  [ -f "$build/CMakeCache.txt" ] || compiler=(-DCMAKE_CXX_COMPILER="$cxx")  # an existing build keeps its compiler
  cmake -S . -B "$build" "${compiler[@]}" -DCMAKE_BUILD_TYPE=Release -DSEXTANT_REQUIRE_ALL_DEPENDENCIES=ON "$@" >/dev/null
}
# build_targets <targets...>: builds them and says how long it took (docs/build_times.md; .ci/run adds these up).
build_targets() {
  local start=$SECONDS
  cmake --build "$build" -j"$jobs" --target "$@"
  echo "sextant: built ${*} in $((SECONDS - start)) s" >&2
}
case "$mode" in
  main)
    configure -DSEXTANT_BUILD_TESTS=OFF -DSEXTANT_BUILD_BENCHMARKS=OFF
    targets=(sextant-run)  # and the program sextant-run hands the data set over to (main.cpp, kHandOvers)
    case " $* " in *globe-stereo*|*stereo:*) targets+=(sextant-globe-stereo) ;;  # stereo images: sextant-globe-stereo
                   *globe*) targets+=(sextant-globe) ;; esac  # --dataset globe hands over to sextant-globe
    case " $* " in *stereo-vi*|*.npz*) targets+=(sextant-vislam) ;; esac  # and stereo-vi / FILE.npz to sextant-vislam
    case " $* " in *mrclam:*) targets+=(sextant-run-mrclam) ;; esac  # mrclam:<dir>:<robot> to sextant-run-mrclam
    case " $* " in *.txt\ *|*.graph\ *) targets+=(sextant-run-isam) ;; esac  # iSAM text files to sextant-run-isam
    build_targets "${targets[@]}"
    exec "$build/examples/sextant-run" "$@" ;;
  test|test-slow)
    configure -DSEXTANT_BUILD_TESTS=ON
    build_targets sextant_tests
    label=(-LE slow)
    [ "$mode" = test-slow ] && label=(-L slow)
    cd "$build" && exec ctest --output-on-failure -j"$jobs" "${label[@]}" "$@" ;;
  test-sanitize)
    build=${SEXTANT_SANITIZE_BUILD_DIR:-build-sanitize}
    cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DCMAKE_CXX_COMPILER=clang++ \
          -DSEXTANT_SANITIZE=address,undefined -DSEXTANT_QUICK_TEST_BUILD=ON \
          -DSEXTANT_REQUIRE_ALL_DEPENDENCIES=ON -DSEXTANT_BUILD_TESTS=ON -DSEXTANT_BUILD_EXAMPLES=OFF \
          -DSEXTANT_BUILD_BENCHMARKS=OFF >/dev/null
    build_targets sextant_sanitized_tests
    export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:strict_string_checks=1}
    export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
    cd "$build" && exec ctest --output-on-failure -j"$jobs" -LE "slow|statistical|install" -E "_NOT_BUILT|^readme\\." "$@" ;;
  test-tsan)
    build=${SEXTANT_TSAN_BUILD_DIR:-build-tsan}
    cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DSEXTANT_SANITIZE=thread \
          -DSEXTANT_BUILD_TESTS=ON -DSEXTANT_BUILD_EXAMPLES=OFF -DSEXTANT_BUILD_BENCHMARKS=OFF >/dev/null
    build_targets concurrent_reads_test monte_carlo_test
    export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}
    cd "$build" && exec ctest --output-on-failure -j"$jobs" -R "^(ConcurrentReads|MonteCarlo)" "$@" ;;
  fuzz)
    build=${SEXTANT_FUZZ_BUILD_DIR:-build-fuzz}
    cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DCMAKE_CXX_COMPILER=clang++ \
          -DSEXTANT_BUILD_FUZZERS=ON -DSEXTANT_BUILD_TESTS=OFF -DSEXTANT_BUILD_EXAMPLES=OFF -DSEXTANT_BUILD_BENCHMARKS=OFF \
          -DSEXTANT_REQUIRE_ALL_DEPENDENCIES=ON >/dev/null
    build_targets sextant_fuzzers
    exec bash cmake/fuzz.sh "$build" "${1:-60}" ;;
  bench)  # g++, in a build directory of its own: docs/benchmarks.md's numbers were measured with it
    build=${SEXTANT_BENCH_BUILD_DIR:-build-bench}
    cxx=${SEXTANT_CXX:-g++}
    configure -DSEXTANT_BUILD_BENCHMARKS=ON
    build_targets sextant_benchmarks
    for b in "$build"/benchmarks/*_benchmark; do "$b" "$@"; done ;;
  *) echo "usage: ./run.sh [main|test|test-slow|test-sanitize|test-tsan|fuzz|bench] [args...]" >&2; exit 2 ;;
esac
