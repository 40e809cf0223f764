#!/usr/bin/env bash
# A speed goal measured as a ratio against a baseline in the same session (the project measures speed
# as ratios against a peer or baseline run beside it, not as times read off one machine): builds one
# Google Benchmark program from an older commit and from this tree with the same compiler, runs the
# two in turn on one pinned core, and prints each pair's times and ratio (older / this tree: the
# first benchmark the filter matches) and their spread.
#
#   benchmarks/against_commit.sh <commit> <program> <filter> [pairs]
#   e.g. benchmarks/against_commit.sh 66d1e35 globe_benchmark 'BM_GlobeSeif120Steps/150/' 8
#
# The older tree is extracted with `git archive` to build-bench-<commit>/src and built in
# build-bench-<commit>/<compiler>; this tree's program is built in build-bench (`./run.sh bench`'s,
# or SEXTANT_BENCH_BUILD_DIR), which must have been configured with the same compiler.
# SEXTANT_CXX chooses the compiler (default g++, as ./run.sh bench). The runs alternate, older
# first, so that a machine whose speed drifts over the session (docs/benchmarks.md: a virtual
# machine's memory handed back to its host) weighs on both sides alike; read the median.
set -euo pipefail
[ $# -ge 3 ] || { sed -n '8,9p' "$0" >&2; exit 2; }
commit=$1 program=$2 filter=$3 pairs=${4:-6}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
source cmake/openblas_coretype.sh  # both programs on OpenBLAS's vector kernels, as ./run.sh runs them
cxx=${SEXTANT_CXX:-g++}
short=$(git rev-parse --short "$commit")
old=$root/build-bench-$short
old_build=$old/$(basename "$cxx")
new_build=${SEXTANT_BENCH_BUILD_DIR:-build-bench}
jobs=$(nproc 2>/dev/null || echo 2)

# A new build directory is configured as ./run.sh configures its own (a missing dependency stops it
# instead of leaving a slower fallback in one of the two builds); an older tree without that option
# ignores it. An existing one keeps its configuration.
configure() {  # configure <source dir> <build dir>
  [ -f "$2/CMakeCache.txt" ] || cmake -S "$1" -B "$2" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$cxx" \
    -DSEXTANT_REQUIRE_ALL_DEPENDENCIES=ON -DSEXTANT_BUILD_BENCHMARKS=ON -DSEXTANT_BUILD_TESTS=OFF > /dev/null
}
build() {  # build <build dir>
  cmake --build "$1" --target "$program" -j"$jobs" > "$1/against_commit_build.log" 2>&1 ||
    { echo "against_commit: building $program in $1 failed: $1/against_commit_build.log" >&2; exit 1; }
}
if [ ! -d "$old/src" ]; then
  mkdir -p "$old/src"
  git archive "$commit" | tar -x -C "$old/src"
fi
configure "$old/src" "$old_build"
configure "$root" "$new_build"
# Before either build: a ratio across compilers would measure the compilers.
compiler_of() { sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$1/CMakeCache.txt"; }
if [ "$(compiler_of "$old_build")" != "$(compiler_of "$new_build")" ]; then
  echo "against_commit: $new_build was configured with $(compiler_of "$new_build"), the older build with" \
    "$(compiler_of "$old_build"): a ratio across compilers measures the compilers (SEXTANT_BENCH_BUILD_DIR names another build)" >&2
  exit 1
fi
echo "against_commit: building $program at $short and in this tree ($cxx)" >&2
build "$old_build"
build "$new_build"

core=$(( $(nproc 2>/dev/null || echo 1) - 1 ))
run() {  # run <program path> <json out>: one pinned run; prints its real time in s
  if ! taskset -c "$core" "$1" --benchmark_filter="$filter" --benchmark_format=json > "$2" 2> "$2.err" || [ ! -s "$2" ]; then
    echo "against_commit: $1 failed or no benchmark matches '$filter':" >&2
    cat "$2.err" >&2
    exit 1
  fi
  python3 -c 'import json,sys
runs=[b for b in json.load(open(sys.argv[1]))["benchmarks"] if b.get("run_type","iteration")=="iteration"]
scale={"s":1,"ms":1e-3,"us":1e-6,"ns":1e-9}
print(" ".join("%.4g" % (b["real_time"] * scale[b["time_unit"]]) for b in runs))' "$2"
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ratios=()
for i in $(seq 1 "$pairs"); do
  t_old=$(run "$old_build/benchmarks/$program" "$tmp/old.json")
  t_new=$(run "$new_build/benchmarks/$program" "$tmp/new.json")
  ratio=$(python3 -c "import sys; print(f'{float(sys.argv[1].split()[0]) / float(sys.argv[2].split()[0]):.2f}')" "$t_old" "$t_new")
  echo "pair $i: $short ${t_old} s, this tree ${t_new} s, ratio ${ratio}x"
  ratios+=("$ratio")
done
python3 -c 'import statistics,sys
r=sorted(float(x) for x in sys.argv[1:])
print(f"ratio over {len(r)} pairs: min {r[0]:.2f}x, median {statistics.median(r):.2f}x, max {r[-1]:.2f}x")' "${ratios[@]}"
