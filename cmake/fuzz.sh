#!/usr/bin/env bash
# Runs every libFuzzer target in <build>/tests/fuzz for <seconds> each (./run.sh fuzz [seconds]).
# Seed corpora are made here, at run time, from ../shared/data and MRPT's demo files (none are
# committed), plus a small settings file of our own. Findings go to <build>/fuzz-findings/; the
# summary (executions, coverage, findings) goes to stdout and <build>/fuzz-summary.md.
set -uo pipefail
build=$1
seconds=${2:-60}
root=$(cd "$(dirname "$0")/.." && pwd)
shared=$root/../shared/data
mrpt=/usr/share/mrpt
corpus=$build/fuzz-corpus
findings=$build/fuzz-findings
mkdir -p "$findings"

# seed <target> <file> [bytes]: copies the file (its first <bytes> bytes, cut at a line end) if it exists.
seed() {
  local dir=$corpus/$1 file=$2 bytes=${3:-}
  mkdir -p "$dir"
  [ -f "$file" ] || { echo "fuzz: seed $file not found, skipped"; return; }
  if [ -n "$bytes" ]; then head -c "$bytes" "$file" | sed '$d' > "$dir/$(basename "$file")"; else cp "$file" "$dir/"; fi
}
seed isam_reader_fuzz "$shared/city_trees/cityTrees10000.txt" 4096
seed isam_reader_fuzz "$shared/city_trees/cityTrees10000_groundtruth.txt" 4096
seed isam_reader_fuzz "$shared/victoria_park/victoria_park.txt" 4096
seed pose_graph_file_fuzz "$shared/pose_graphs/intel.g2o" 4096
seed pose_graph_file_fuzz "$shared/pose_graphs/sphere2500.g2o" 4096
seed pose_graph_file_fuzz "$shared/pose_graphs/manhattan.g2o" 2048
seed pose_graph_file_fuzz "$mrpt/datasets/graph_2d_circle_50nodes.graph"
for f in "$mrpt"/datasets/kf-slam_*ground_truth*.txt; do seed kf_slam_ground_truth_fuzz "$f" 4096; done
for f in "$mrpt"/datasets/kf-slam_demo.rawlog "$mrpt"/datasets/kf-slam_6D_demo.rawlog; do seed rawlog_fuzz "$f"; done
for f in "$mrpt"/config_files/kf-slam/EKF-SLAM_test_2d.ini "$mrpt"/config_files/kf-slam/EKF-SLAM_6D_test.ini; do
  seed runner_config_fuzz "$f"
done
# MRCLAM: the five files of robot 1 (their first 2 KB), joined with "%%" lines as the target splits them.
mrclam=$shared/mrclam/MRCLAM_Dataset6
if [ -d "$mrclam" ]; then
  mkdir -p "$corpus/mrclam_reader_fuzz"
  for f in Barcodes Landmark_Groundtruth Robot1_Odometry Robot1_Measurement Robot1_Groundtruth; do
    head -c 2048 "$mrclam/$f.dat" | sed '$d'
    echo "%%"
  done > "$corpus/mrclam_reader_fuzz/dataset6_robot1"
else
  echo "fuzz: seed $mrclam not found, skipped"
fi
# .npz: a small data set of our own, and cuts of the seed's files (20 landmarks, 10 frames), made
# with numpy (python3-numpy comes with python3-matplotlib).
mkdir -p "$corpus/npz_reader_fuzz"
/usr/bin/python3 - "$corpus/npz_reader_fuzz" "$shared/ece276a" <<'PY' || echo "fuzz: npz seeds not made (numpy missing?)"
import os, sys
import numpy as np
out, data = sys.argv[1], sys.argv[2]
T, M = 4, 3
features = -np.ones((4, M, T))
features[:, 0, :2] = [[700, 710], [200, 201], [650, 655], [200, 201]]
np.savez(os.path.join(out, "own.npz"), time_stamps=np.arange(T)[None, :] * 0.1, linear_velocity=np.ones((3, T)),
         angular_velocity=np.zeros((3, T)), features=features, K=np.array([[700, 0, 600], [0, 700, 180], [0, 0, 1.0]]),
         b=np.array(0.5), imu_T_cam=np.eye(4))
for name in ("03.npz", "0027_clean.npz"):
    path = os.path.join(data, name)
    if not os.path.exists(path):
        print("fuzz: seed " + path + " not found, skipped")
        continue
    d = dict(np.load(path))
    d["features"] = d["features"][:, :20, :10]
    for key in ("time_stamps", "linear_velocity", "angular_velocity", "rotational_velocity"):
        if key in d:
            d[key] = d[key][:, :10]
    np.savez_compressed(os.path.join(out, "cut_" + name), **d)
PY
mkdir -p "$corpus/runner_config_fuzz"
printf '[ship]\nruns = 2\nsigma_heading_deg = 15\n[ekf]\ncovariance_update = joseph\n[seif]\nmax_active = 4 // four\n[globe]\nseif_active = 4 8\n' \
  > "$corpus/runner_config_fuzz/sextant.ini"

# A Monte Carlo study's record file (eval/study_records.hpp, docs/monte_carlo_clusters.md): shard 1 of
# 2 of a 3-run study, one run scored, one failed.
mkdir -p "$corpus/study_records_fuzz"
columns='dataset\tcell\tlabel\tpose_dof\tseed\tsteps\tpose_mae\tpose_rmse\tpose_rmse_aligned\tpose_mae_aligned\tmap_mae\tmap_mae_over_time\tmap_mae_aligned\tpose_nees_inside\tmap_nees_inside\tpose_anees\ttotal_seconds\tfailed_steps\tfirst_failure\tfailure\textras'
printf "# sextant run records 1\nprogram\tsextant-run\nstudy\t--runs 3\nruns\t3\nfirst_seed\t1\nshard\t1/2\n${columns}\nship\tekf\tEKF-SLAM\t2\t2\t1390\t8.71\t12.3\t11.1\t9.33\t2.38\t2.60\t1.75\t1\t0.96\t0.587\t0.014\t1\tstep 3: update: S is not positive definite\t\tassociation_precision=0.5,b=inf\nship\tekf\tEKF-SLAM\t2\t3\t0\tnan\tnan\tnan\tnan\tnan\tnan\tnan\tnan\tnan\tnan\t0\t0\t\tfailed\t\nend\t2\n" \
  > "$corpus/study_records_fuzz/shard"

# Stereo sequences: a calibration of our own (32x24 images) with one pair, and one with a starting
# state; the parts are separated by "%%" lines (tests/fuzz/stereo_sequence_fuzz.cpp).
mkdir -p "$corpus/stereo_sequence_fuzz"
calib='%%YAML:1.0\nK: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: [100, 0, 16, 0, 100, 12, 0, 0, 1]\nbaseline: 0.1\nimage_width: 32\nimage_height: 24\ndt: 0.1\n'
printf "${calib}%%%%\n000000.png\n000001.png\n%%%%\n000000.png\n000001.png\n" > "$corpus/stereo_sequence_fuzz/pair"
printf "${calib}initial_state: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\ninitial_sigma: [1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n%%%%\n000000.png\n%%%%\n000000.png\n" \
  > "$corpus/stereo_sequence_fuzz/with_state"

summary=$build/fuzz-summary.md
# fuzz_target <target>: runs it for $seconds s; writes its summary row to $build/fuzz-<name>.row and
# returns non-zero on a finding.
fuzz_target() {
  local target=$1 name rc execs cov ft units found
  name=$(basename "$target")
  mkdir -p "$corpus/$name"
  local log=$build/fuzz-$name.log
  echo "fuzz: $name for $seconds s"
  # -report_slow_units at the timeout: a unit slower than libFuzzer's default 10 s but under 20 s is
  # no finding (docs/reliability.md: a timeout is 20 s), only its artifact would have failed the run.
  "$target" "$corpus/$name" -max_total_time="$seconds" -timeout=20 -report_slow_units=20 -rss_limit_mb=2560 -max_len=65536 \
    -print_final_stats=1 -artifact_prefix="$findings/$name-" > "$log" 2>&1
  rc=$?
  execs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | awk '{print $2}')
  cov=$(grep -oE '(DONE|pulse|REDUCE|NEW|INITED) +cov: [0-9]+' "$log" | tail -1 | awk '{print $NF}')
  ft=$(grep -oE ' ft: [0-9]+' "$log" | tail -1 | awk '{print $NF}')
  units=$(ls "$corpus/$name" | wc -l)
  found=$(ls "$findings" | grep -c "^$name-" || true)
  echo "| $name | $seconds | ${execs:-?} | ${cov:-?} | ${ft:-?} | $units | $found |" > "$build/fuzz-$name.row"
  if [ $rc -ne 0 ] || [ "$found" -ne 0 ]; then
    echo "fuzz: $name FAILED (exit $rc); its log: $log"
    grep -E "ERROR|runtime error|SUMMARY|uncaught|Test unit written" "$log" | head -20
    return 1
  fi
}
# One target per core at a time (libFuzzer runs on one thread): each still gets its $seconds.
jobs=$(nproc 2>/dev/null || echo 2)
status=0
running=0
for target in "$build"/tests/fuzz/*_fuzz; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || status=1
    running=$((running - 1))
  fi
  fuzz_target "$target" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || status=1
  running=$((running - 1))
done
{
  echo "| target | seconds | executions | coverage (edges) | features | corpus | findings |"
  echo "|---|---|---|---|---|---|---|"
  for target in "$build"/tests/fuzz/*_fuzz; do cat "$build/fuzz-$(basename "$target").row"; done
} > "$summary"
cat "$summary"
exit $status
