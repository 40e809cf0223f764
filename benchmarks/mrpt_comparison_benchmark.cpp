// MRPT's own EKF-SLAM (CRangeBearingKFSLAM2D, as its kf-slam app runs it) and sextant's EkfSlam on
// the same rawlog, kf-slam_demo.rawlog, in one process: same noise (MRPT's EKF-SLAM_test_2d.ini:
// range 0.03 m, bearing 0.1 deg), no logging, no 3D, analytic Jacobians in both. Each iteration runs
// the whole log from an empty map; items_per_second is steps per second, map_error_mm the mean
// landmark error against the ground truth. The rawlog is decoded before timing starts, for both.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/slam/CRangeBearingKFSLAM2D.h>
#include <numbers>
#include <sextant/backends/ekf_slam.hpp>
#include <sextant/eval/metrics.hpp>
#include <sextant/mrpt/rawlog.hpp>

namespace {

constexpr const char* kRawlog = "/usr/share/mrpt/datasets/kf-slam_demo.rawlog";
constexpr double kStdRange = 0.03, kStdBearing = 0.1 * std::numbers::pi / 180.0;

using Pairs = std::vector<std::pair<mrpt::obs::CActionCollection::Ptr, mrpt::obs::CSensoryFrame::Ptr>>;

const Pairs& mrpt_pairs() {
  static const Pairs pairs = [] {
    mrpt::obs::CRawlog log;
    if (!log.loadFromRawLogFile(kRawlog)) throw std::runtime_error(std::string("cannot read ") + kRawlog);
    Pairs out;
    mrpt::obs::CActionCollection::Ptr action;
    mrpt::obs::CSensoryFrame::Ptr frame;
    for (std::size_t entry = 0; log.getActionObservationPair(action, frame, entry);) out.emplace_back(action, frame);
    return out;
  }();
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
  double sum = 0.0;
  for (const auto& [id, position] : map) sum += (position - truth.at(id)).norm();
  return 1000.0 * sum / static_cast<double>(map.size());
}

void BM_MrptCRangeBearingKFSLAM2D(benchmark::State& state) {
  if (!std::filesystem::exists(kRawlog)) return state.SkipWithError("kf-slam_demo.rawlog not found (mrpt-common)");
  const auto& pairs = mrpt_pairs();
  std::vector<std::pair<sextant::LandmarkId, Eigen::Vector2d>> map;
  for (auto _ : state) {
    mrpt::slam::CRangeBearingKFSLAM2D filter;
    filter.setVerbosityLevel(mrpt::system::LVL_ERROR);
    filter.options.std_sensor_range = static_cast<float>(kStdRange);
    filter.options.std_sensor_yaw = static_cast<float>(kStdBearing);
    for (auto [action, frame] : pairs) filter.processActionObservation(action, frame);
    state.PauseTiming();
    mrpt::poses::CPosePDFGaussian pose;
    std::vector<mrpt::math::TPoint2D> landmarks;
    std::map<unsigned int, mrpt::maps::CLandmark::TLandmarkID> ids;
    mrpt::math::CVectorDouble full_state;
    mrpt::math::CMatrixDouble full_cov;
    filter.getCurrentState(pose, landmarks, ids, full_state, full_cov);
    map.clear();
    for (std::size_t i = 0; i < landmarks.size(); ++i)
      map.emplace_back(ids.at(static_cast<unsigned>(i)), Eigen::Vector2d(landmarks[i].x, landmarks[i].y));
    state.ResumeTiming();
  }
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
