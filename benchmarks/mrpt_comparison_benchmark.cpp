// MRPT's own EKF-SLAM (CRangeBearingKFSLAM2D, as its kf-slam app runs it) and sextant's EkfSlam on
// the same rawlog, kf-slam_demo.rawlog, in one process: same noise (MRPT's EKF-SLAM_test_2d.ini:
// range 0.03 m, bearing 0.1 deg), no logging, no 3D, analytic Jacobians in both. Each iteration runs
// the whole log from an empty map; items_per_second is steps per second, map_error_mm the mean
// landmark error against the ground truth. The rawlog is decoded before timing starts, for both; the
// MRPT row's time includes reading its final state (getCurrentState), a few microseconds.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <numbers>
#include <sextant/backends/ekf_slam.hpp>
#include <sextant/eval/metrics.hpp>
#include <sextant/mrpt/rawlog.hpp>

#include "support/mrpt_kf_slam.hpp"

namespace {

constexpr const char* kRawlog = "/usr/share/mrpt/datasets/kf-slam_demo.rawlog";
constexpr double kStdRange = 0.03, kStdBearing = 0.1 * std::numbers::pi / 180.0;

const sextant::test::MrptActionFramePairs& mrpt_pairs() {
  static const auto pairs = sextant::test::read_mrpt_pairs(kRawlog);
  return pairs;
}

const sextant::mrpt_io::RawlogDataset2D& sextant_data() {
  static const auto data = [] {
    sextant::mrpt_io::RawlogOptions options;
    options.std_range = kStdRange;
    options.std_yaw = kStdBearing;
    auto d = sextant::mrpt_io::read_rawlog_2d(kRawlog, options);
    sextant::mrpt_io::attach_ground_truth(d, *sextant::mrpt_io::find_ground_truth(kRawlog));
    return d;
  }();
  return data;
}

double mean_map_error_mm(const std::map<sextant::LandmarkId, Eigen::Vector2d>& truth,
                         const std::vector<std::pair<sextant::LandmarkId, Eigen::Vector2d>>& map) {
  return 1000.0 * sextant::test::mean_map_error(truth, map);
}

void BM_MrptCRangeBearingKFSLAM2D(benchmark::State& state) {
  if (!std::filesystem::exists(kRawlog)) return state.SkipWithError("kf-slam_demo.rawlog not found (mrpt-common)");
  const auto& pairs = mrpt_pairs();
  std::vector<std::pair<sextant::LandmarkId, Eigen::Vector2d>> map;
  for (auto _ : state) map = sextant::test::run_mrpt_kf_slam_2d(pairs, kStdRange, kStdBearing);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(pairs.size()));
  state.counters["map_error_mm"] = mean_map_error_mm(sextant_data().true_landmarks, map);
  state.counters["landmarks"] = static_cast<double>(map.size());
}

void BM_SextantEkfSlam(benchmark::State& state) {
  if (!std::filesystem::exists(kRawlog)) return state.SkipWithError("kf-slam_demo.rawlog not found (mrpt-common)");
  const auto& data = sextant_data();
  std::vector<std::pair<sextant::LandmarkId, Eigen::Vector2d>> map;
  for (auto _ : state) {
    sextant::EkfSlam<sextant::Se2Odometry, sextant::RangeBearing2D> filter(data.motion, data.sensor, data.prior);
    for (const auto& step : data.steps) {
      filter.predict(step.control, step.dt);
      filter.update(step.observations);
    }
    state.PauseTiming();
    map.clear();
    for (const auto& landmark : filter.map()) map.emplace_back(landmark.id, landmark.mean);
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(data.steps.size()));
  state.counters["map_error_mm"] = mean_map_error_mm(data.true_landmarks, map);
  state.counters["landmarks"] = static_cast<double>(map.size());
}

}  // namespace

BENCHMARK(BM_MrptCRangeBearingKFSLAM2D)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SextantEkfSlam)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
