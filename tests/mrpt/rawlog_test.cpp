#include "sextant/mrpt/rawlog.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <numbers>

#include "mrpt/mrpt_demo_data.hpp"
#include "support/bounded_mrpt_alloc.hpp"  // new and MRPT's aligned_malloc throw above 256 MiB (corrupt-length tests)
#include "support/nees_bound.hpp"
#include "support/temp_path.hpp"
#ifdef SEXTANT_HAS_MRPT_SLAM
#include "support/mrpt_kf_slam.hpp"
#endif
#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/fast_slam.hpp"
#include "sextant/backends/graph_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/eval/experiment.hpp"

namespace sextant::mrpt_io {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// Worst |residual| / sigma of every measurement of the first `steps` steps, predicted from the
/// true pose and landmark: small only if the model reads MRPT's measurements the way MRPT made them.
template <class Dataset>
double worst_normalized_residual_at_truth(const Dataset& data, std::size_t steps) {
  double worst = 0.0;
  const auto sigma = data.sensor.Q.diagonal().cwiseSqrt().eval();
  for (std::size_t k = 0; k < steps; ++k)
    for (const auto& o : data.steps[k].observations) {
      const auto predicted = data.sensor.predict(data.true_poses[k + 1], data.true_landmarks.at(o.landmark_id));
      worst = std::max(worst, data.sensor.residual(o.z, predicted.z).cwiseQuotient(sigma).cwiseAbs().maxCoeff());
    }
  return worst;
}

TEST(KfSlamDemo, ReadsStepsSensorAndGroundTruth) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_demo.rawlog");
  auto data = read_rawlog_2d(testing::mrpt_demo("kf-slam_demo.rawlog"));
  EXPECT_EQ(detect_rawlog_kind(data.path), RawlogKind::planar);
  ASSERT_EQ(data.steps.size(), 249u);  // 250 frames and 250 actions; the first frame precedes any action
  EXPECT_EQ(data.steps.front().observations.size(), 27u);
  EXPECT_NEAR(std::sqrt(data.sensor.Q(0, 0)), 0.01, 1e-7);
  EXPECT_NEAR(std::sqrt(data.sensor.Q(1, 1)), 0.1 * kDeg, 1e-7);
  EXPECT_NEAR(data.steps.back().control.cov(0, 0), 0.0016, 1e-9);
  const auto files = find_ground_truth(data.path);
  ASSERT_TRUE(files);
  attach_ground_truth(data, *files);
  EXPECT_EQ(data.true_poses.size(), 250u);
  EXPECT_EQ(data.true_landmarks.size(), 70u);
  EXPECT_LT(worst_normalized_residual_at_truth(data, data.steps.size()), 5.0);
}

#ifdef SEXTANT_HAS_MRPT_SLAM  // CMake reports mrpt-slam missing (and run.sh fails the build)
TEST(KfSlamDemo, EkfMapErrorIsAtMostMrptKfSlamWithTheSameNoise) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_demo.rawlog");
  // The peer, run here: MRPT's CRangeBearingKFSLAM2D as its kf-slam app runs it with
  // EKF-SLAM_test_2d.ini (range 0.03 m, bearing 0.1 deg).
  const std::string path = testing::mrpt_demo("kf-slam_demo.rawlog");
  const auto truth_files = find_ground_truth(path);
  ASSERT_TRUE(truth_files);
  RawlogOptions options;
  options.std_range = 0.03;
  options.std_yaw = 0.1 * kDeg;
  options.at_rest_noise_scale = 1.0;  // kf-slam reads the opening steps at rest as stated: the same input
  auto data = read_rawlog_2d(path, options);
  attach_ground_truth(data, *truth_files);
  const double mrpt_error =
      test::mean_map_error(data.true_landmarks, test::run_mrpt_kf_slam_2d(test::read_mrpt_pairs(path), 0.03, 0.1 * kDeg));
  EkfSlam<Se2Odometry, RangeBearing2D> ekf(data.motion, data.sensor, data.prior);
  const auto run = eval::evaluate_run(ekf, data, 2);
  EXPECT_EQ(run.map_error.size(), 70u);
  std::printf("mean map error: sextant EKF %.4f mm, MRPT kf-slam %.4f mm\n", 1e3 * eval::mean(run.map_error),
              1e3 * mrpt_error);
  EXPECT_GT(mrpt_error, 0.0);
  EXPECT_LE(eval::mean(run.map_error), mrpt_error);
}
#endif

TEST(KfSlam6dDemos, SensorModelReproducesTheMeasurementsFromGroundTruth) {
  for (const char* name : {"kf-slam_6D_demo.rawlog", "kf-slam_6D_demo_noncentered.rawlog"}) {
    SCOPED_TRACE(name);
    if (!std::filesystem::exists(testing::mrpt_demo(name))) GTEST_SKIP() << name << " not found (mrpt-common)";
    auto data = read_rawlog_3d(testing::mrpt_demo(name));
    EXPECT_EQ(detect_rawlog_kind(data.path), RawlogKind::spatial);
    ASSERT_EQ(data.steps.size(), 599u);
    attach_ground_truth(data, *find_ground_truth(data.path));
    EXPECT_LT(worst_normalized_residual_at_truth(data, 50), 5.0);
  }
}

TEST(KfSlam6dDemos, EveryBackEndMapsTheSpatialDemo) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_6D_demo.rawlog");
  auto data = read_rawlog_3d(testing::mrpt_demo("kf-slam_6D_demo.rawlog"));
  attach_ground_truth(data, *find_ground_truth(data.path));
  using Motion = Se3Odometry;
  using Sensor = RangeBearing3D;
  // The EKF against theory: every landmark inside its chi-square bound (1% overall). The others
  // against the EKF, run here: SEIF and GraphSLAM within 2x of its map error (GraphSLAM is the
  // smoother, SEIF the sparsified filter: neither should lose more); FastSLAM, with sextant-run's
  // settings, within 4x of its map error after rigid alignment (its unaligned error is dominated by
  // the gauge; on this log 8 seeds ranged 1.4x-3.5x: docs/results/fastslam_gap.md).
  EkfSlam<Motion, Sensor> ekf(data.motion, data.sensor, data.prior);
  const auto ekf_run = eval::evaluate_run(ekf, data, 3);
  for (double nees : ekf_run.map_nees) EXPECT_LT(nees, test::nees_bound(3, ekf_run.map_nees.size()));
  const double ekf_error = eval::mean(ekf_run.map_error);
  SeifSlam<Motion, Sensor> seif(data.motion, data.sensor, data.prior, {.max_active = 8});
  EXPECT_LT(eval::mean(eval::evaluate_run(seif, data, 3).map_error), 2.0 * ekf_error);
  GraphSlam<Motion, Sensor> graph(data.motion, data.sensor, data.prior);
  const auto graph_run = eval::evaluate_smoothed_run(graph, data, 3);
  EXPECT_LT(eval::mean(graph_run.map_error), 2.0 * ekf_error);
  ASSERT_TRUE(graph_run.optimization);  // the run records how its optimization ended
  EXPECT_TRUE(graph_run.optimization->converged);
  EXPECT_LE(graph_run.optimization->iterations, GraphOptions{}.max_iterations);
  GraphSlam<Motion, Sensor> one_step(data.motion, data.sensor, data.prior, {.max_iterations = 1});
  const auto one_step_run = eval::evaluate_smoothed_run(one_step, data, 3);  // from dead reckoning: not converged
  ASSERT_TRUE(one_step_run.optimization);
  EXPECT_FALSE(one_step_run.optimization->converged);
  EXPECT_EQ(one_step_run.optimization->iterations, 1);
  FastSlam<Motion, Sensor> fast(data.motion, data.sensor, data.prior,
                                {.particles = 100, .resample_threshold = 0.1, .map_estimate = FastSlamMap::weighted_average});
  const auto fast_run = eval::evaluate_run(fast, data, 3);
  EXPECT_EQ(fast_run.map_error.size(), ekf.map().size());
  EXPECT_LT(eval::mean(fast_run.map_error_aligned), 4.0 * eval::mean(ekf_run.map_error_aligned));
}

TEST(KfSlamDemo, FastSlamTwoTracksWithinHalfAgainTheEkf) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_demo.rawlog");
  // Issue 34's goals, against the EKF run here: FastSLAM 2.0 with sextant-run's settings, mean over
  // 16 seeds: pose error and aligned map error within 1.5x of the EKF's. Before round three's
  // fixes its pose error was 7.8x: the particles sampled the first step's odometry noise (4 cm while
  // the robot stood still) and the map of the surviving ancestor kept it. The pose NEES: issue 34
  // asks for 80% of the steps inside the 95% bound, a goal set while the log's opening steps at rest
  // were read with their stated noise, which widened every filter's covariance by noise that never
  // happened (EKF 100% inside then). Read as at rest, the EKF run here is the reference: FastSLAM's
  // mean share may trail the EKF's by at most 10 points. One seed's share varies by ~9 points, so a
  // mean of three (standard error ~5) could not tell a 10-point gap from none and passed or failed
  // with the random stream (docs/results/fastslam_gap.md, "Resampling before the draw"); 16 seeds
  // bring the standard error to ~2 points.
  auto data = read_rawlog_2d(testing::mrpt_demo("kf-slam_demo.rawlog"));
  attach_ground_truth(data, *find_ground_truth(data.path));
  EkfSlam<Se2Odometry, RangeBearing2D> ekf(data.motion, data.sensor, data.prior);
  const auto ekf_run = eval::scores_of(eval::evaluate_run(ekf, data, 2), 3, 2);
  double pose = 0.0, map = 0.0, inside = 0.0;
  constexpr int kSeeds = 16;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    FastSlam<Se2Odometry, RangeBearing2D> fast(
        data.motion, data.sensor, data.prior,
        {.particles = 100, .resample_threshold = 0.1, .map_estimate = FastSlamMap::weighted_average, .seed = seed});
    const auto run = eval::scores_of(eval::evaluate_run(fast, data, 2), 3, 2);
    pose += run.pose_mae / kSeeds;
    map += run.map_mae_aligned / kSeeds;
    inside += run.pose_nees_inside / kSeeds;
    std::printf("seed %u: pose NEES inside %.1f%%\n", static_cast<unsigned>(seed), 100.0 * run.pose_nees_inside);
  }
  std::printf("kf-slam_demo, FastSLAM 2.0 / EKF: pose MAE %.5f / %.5f m, aligned map MAE %.5f / %.5f m, pose NEES "
              "inside %.1f%% / %.1f%%\n",
              pose, ekf_run.pose_mae, map, ekf_run.map_mae_aligned, 100.0 * inside, 100.0 * ekf_run.pose_nees_inside);
  EXPECT_LT(pose, 1.5 * ekf_run.pose_mae);
  EXPECT_LT(map, 1.5 * ekf_run.map_mae_aligned);
  EXPECT_GE(inside, ekf_run.pose_nees_inside - 0.1);
}

// ---- Logs written here with MRPT's own serialization --------------------------------------------

class WrittenRawlog : public ::testing::Test {
 protected:
  std::filesystem::path dir =
      test::unique_temp_path(std::string("rawlog_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { std::filesystem::create_directories(dir); }
  void TearDown() override { std::filesystem::remove_all(dir); }

  static ::mrpt::obs::CObservationBearingRange::Ptr bearing(std::vector<std::pair<int, float>> id_range,
                                                            float pitch = 0.0f) {
    auto obs = ::mrpt::obs::CObservationBearingRange::Create();
    obs->sensor_std_range = 0.02f;
    obs->sensor_std_yaw = 0.01f;
    obs->sensor_std_pitch = 0.01f;
    for (const auto& [id, range] : id_range) {
      ::mrpt::obs::CObservationBearingRange::TMeasurement m;
      m.range = range;
      m.yaw = 0.25f;
      m.pitch = pitch;
      m.landmarkID = id;
      obs->sensedData.push_back(m);
    }
    return obs;
  }
  static ::mrpt::obs::CObservationOdometry::Ptr odometry(double x, double y, double phi) {
    auto obs = ::mrpt::obs::CObservationOdometry::Create();
    obs->odometry = ::mrpt::poses::CPose2D(x, y, phi);
    return obs;
  }
  /// An odometry action as MRPT's drivers make it: the increment through MRPT's Gaussian motion
  /// model, which computes the covariance (MRPT re-derives it from the raw increment on reading).
  static ::mrpt::obs::CActionCollection::Ptr action(double x, double y, double phi) {
    ::mrpt::obs::CActionRobotMovement2D move;
    ::mrpt::obs::CActionRobotMovement2D::TMotionModelOptions model;
    model.modelSelection = ::mrpt::obs::CActionRobotMovement2D::mmGaussian;
    move.computeFromOdometry(::mrpt::poses::CPose2D(x, y, phi), model);
    auto actions = ::mrpt::obs::CActionCollection::Create();
    actions->insert(move);
    return actions;
  }
  static Eigen::Matrix3d covariance_of(const ::mrpt::obs::CActionCollection::Ptr& actions) {
    return ::mrpt::poses::CPosePDFGaussian(*actions->getBestMovementEstimation()->poseChange).cov.asEigen();
  }
  static ::mrpt::obs::CSensoryFrame::Ptr frame(const ::mrpt::obs::CObservation::Ptr& obs) {
    auto sf = ::mrpt::obs::CSensoryFrame::Create();
    sf->insert(obs);
    return sf;
  }

  /// Writes objects in order; gzip-compressed unless `plain`.
  template <class... Objects>
  std::string write(const std::string& name, bool plain, const Objects&... objects) {
    const std::string path = (dir / name).string();
    if (plain) {
      ::mrpt::io::CFileOutputStream out(path);
      auto archive = ::mrpt::serialization::archiveFrom(out);
      (archive << ... << *objects);
    } else {
      ::mrpt::io::CFileGZOutputStream out(path);
      auto archive = ::mrpt::serialization::archiveFrom(out);
      (archive << ... << *objects);
    }
    return path;
  }

  /// A copy of the log at `path`, named `name` in the test's directory, whose bytes `edit` changed
  /// (a log damaged or altered on purpose); its path.
  template <class Edit>
  std::string edited_copy(const std::string& path, const std::string& name, Edit edit) const {
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    edit(bytes);
    const auto copy = (dir / name).string();
    std::ofstream(copy, std::ios::binary) << bytes;
    return copy;
  }

  /// The parse_error message of reading `path` as a planar log (fails the test if none).
  static std::string error_of(const std::string& path) {
    try {
      read_rawlog_2d(path);
    } catch (const parse_error& e) {
      return e.what();
    }
    ADD_FAILURE() << "no parse_error for " << path;
    return {};
  }
};

TEST_F(WrittenRawlog, GroundTruthIsFoundUnderTheDemosAndUnderSimulLandmarksNames) {
  const auto touch = [](const std::filesystem::path& file) { std::ofstream(file) << "0 0 0\n"; };
  const auto log = (dir / "run.rawlog").string();
  EXPECT_FALSE(find_ground_truth(log));
  touch(dir / "run.rawlog_ground_truth.txt");  // simul-landmarks writes <name>.rawlog_ground_truth*.txt
  EXPECT_FALSE(find_ground_truth(log)) << "a map without a path is not ground truth";
  touch(dir / "run.rawlog_ground_truth_robot_path.txt");
  ASSERT_TRUE(find_ground_truth(log));
  EXPECT_EQ(find_ground_truth(log)->path, log + "_ground_truth_robot_path.txt");
  touch(dir / "run_ground_truth.txt");  // the demos' <stem>_ground_truth*.txt come first
  touch(dir / "run_ground_truth_robot_path.txt");
  EXPECT_EQ(find_ground_truth(log)->map, (dir / "run_ground_truth.txt").string());
}

TEST_F(WrittenRawlog, ActionFrameLogBecomesStepsAndSkipsTheLeadingFrame) {
  const auto first = action(0.5, 0.0, 0.1);
  const auto path = write("log.rawlog", false, frame(bearing({{1, 2.0f}})), first,
                          frame(bearing({{1, 1.5f}, {2, 3.0f}})), action(0.4, 0.1, -0.2), frame(bearing({{2, 2.5f}})),
                          action(1.0, 0.0, 0.0));
  const auto data = read_rawlog_2d(path);
  ASSERT_EQ(data.steps.size(), 2u);  // the leading frame and the trailing action are skipped
  EXPECT_TRUE(data.steps[0].control.delta.isApprox(Eigen::Vector3d(0.5, 0.0, 0.1), 1e-12));
  EXPECT_TRUE(data.steps[0].control.cov.isApprox(covariance_of(first), 1e-6));  // stored as float
  EXPECT_GT(data.steps[0].control.cov(2, 2), 0.0);
  ASSERT_EQ(data.steps[0].observations.size(), 2u);
  EXPECT_EQ(data.steps[0].observations[1].landmark_id, 2u);
  EXPECT_NEAR(data.steps[0].observations[1].z(0), 3.0, 1e-6);
  EXPECT_NEAR(std::sqrt(data.sensor.Q(0, 0)), 0.02, 1e-7);
}

TEST_F(WrittenRawlog, AStepAtRestKeepsItsStatedNoiseOnlyWhenAskedTo) {
  // MRPT's simul-landmarks opens every log with steps at rest: a zero increment it adds no noise to,
  // stated with its usual covariance. A zero increment is read as at rest, a moving one as stated.
  const auto at_rest = action(0.0, 0.0, 0.0), moving = action(0.5, 0.0, 0.1);
  const auto path = write("rest.rawlog", false, frame(bearing({{1, 2.0f}})), at_rest, frame(bearing({{1, 2.0f}})), moving,
                          frame(bearing({{1, 1.5f}})));
  ASSERT_GT(covariance_of(at_rest).trace(), 0.0);
  const auto data = read_rawlog_2d(path);
  ASSERT_EQ(data.steps.size(), 2u);
  EXPECT_TRUE(data.steps[0].control.cov.isApprox(covariance_of(at_rest) * 1e-6, 1e-6));  // default scale 1e-3
  EXPECT_TRUE(data.steps[1].control.cov.isApprox(covariance_of(moving), 1e-6));
  RawlogOptions as_stated;
  as_stated.at_rest_noise_scale = 1.0;
  EXPECT_TRUE(read_rawlog_2d(path, as_stated).steps[0].control.cov.isApprox(covariance_of(at_rest), 1e-6));
}

TEST_F(WrittenRawlog, ObservationOnlyLogUsesOdometryDifferencesAndConfiguredNoise) {
  const auto path = write("obs.rawlog", false, bearing({{7, 1.0f}}), odometry(1.0, 1.0, 0.0), bearing({{7, 2.0f}}),
                          odometry(1.0, 2.0, std::numbers::pi / 2), bearing({{7, 1.0f}, {8, 4.0f}}));
  RawlogOptions options;
  options.odometry_std = {0.2, 0.3, 0.05};
  const auto data = read_rawlog_2d(path, options);
  ASSERT_EQ(data.steps.size(), 1u);  // the first reading only sets the origin of the differences
  // From (1, 1, 0) to (1, 2, 90 deg): 1 m along the robot's y axis, a quarter turn.
  EXPECT_TRUE(data.steps[0].control.delta.isApprox(Eigen::Vector3d(0.0, 1.0, std::numbers::pi / 2), 1e-9));
  EXPECT_NEAR(data.steps[0].control.cov(1, 1), 0.09, 1e-12);
  EXPECT_EQ(data.steps[0].observations.size(), 2u);
}

TEST_F(WrittenRawlog, BadLogsGiveOneLineErrorsNamingFileAndProblem) {
  const auto missing = (dir / "missing.rawlog").string();
  EXPECT_NE(error_of(missing).find(missing + ": cannot open file"), std::string::npos);

  const auto empty = (dir / "empty.rawlog").string();
  std::ofstream(empty).close();
  EXPECT_NE(error_of(empty).find("empty rawlog"), std::string::npos);

  const auto garbage = (dir / "garbage.rawlog").string();
  std::ofstream(garbage) << "this is not a rawlog at all, just some text that MRPT cannot deserialize\n";
  EXPECT_NE(error_of(garbage).find(garbage + ": entry 0: truncated or malformed"), std::string::npos);

  // Cut a plain log in the middle of its last entry.
  const auto whole = write("whole.rawlog", true, action(0.5, 0.0, 0.1), frame(bearing({{1, 2.0f}, {2, 3.0f}})),
                           action(0.5, 0.0, 0.1), frame(bearing({{1, 2.0f}, {2, 3.0f}})));
  const auto size = std::filesystem::file_size(whole);
  const auto truncated = (dir / "truncated.rawlog").string();
  std::filesystem::copy_file(whole, truncated);
  std::filesystem::resize_file(truncated, size - 20);
  EXPECT_NE(error_of(truncated).find(truncated + ": entry 3: truncated or malformed"), std::string::npos);
  EXPECT_EQ(read_rawlog_2d(whole).steps.size(), 2u);

  // A log of a sensor MRPT knows but this build does not register (MRPT's own rot_scan_2d.rawlog
  // holds CObservationRotatingScan, of mrpt-maps): named as such, not called malformed. Made here
  // by renaming the observation's class in the bytes of a good log.
  const std::string known_class = "CObservationBearingRange", unknown_class = "CObservationBearingRangX";
  std::size_t renamed = 0;
  const auto foreign = edited_copy(whole, "foreign.rawlog", [&](std::string& bytes) {
    for (auto at = bytes.find(known_class); at != std::string::npos; at = bytes.find(known_class, at), ++renamed)
      bytes.replace(at, known_class.size(), unknown_class);
  });
  ASSERT_GT(renamed, 0u);
  const auto foreign_error = error_of(foreign);
  EXPECT_NE(foreign_error.find(foreign + ": entry 1: an object of class mrpt::obs::CObservationBearingRangX, which "
                                         "this reader cannot read"),
            std::string::npos)
      << foreign_error;
  EXPECT_EQ(foreign_error.find("malformed"), std::string::npos) << foreign_error;

  const auto mixed = write("mixed.rawlog", false, action(0.5, 0.0, 0.1), frame(bearing({{4, 2.0f}})),
                           action(0.5, 0.0, 0.1), frame(bearing({{-1, 2.0f}})));
  EXPECT_NE(error_of(mixed).find("entry 3: some landmarks have ids and some have none"), std::string::npos);

  const auto nan = write("nan.rawlog", false, action(0.5, 0.0, 0.1), frame(bearing({{3, std::nanf("")}})));
  EXPECT_NE(error_of(nan).find("landmark 3: measurement contains NaN or Inf"), std::string::npos);

  const auto pitched = write("pitched.rawlog", false, action(0.5, 0.0, 0.1), frame(bearing({{3, 1.0f}}, 0.2f)));
  EXPECT_NE(error_of(pitched).find("pitch != 0"), std::string::npos);
  EXPECT_EQ(detect_rawlog_kind(pitched), RawlogKind::spatial);

  for (const auto& path : {missing, empty, garbage, truncated, mixed, nan, pitched})
    EXPECT_EQ(error_of(path).find('\n'), std::string::npos) << path;
}

TEST_F(WrittenRawlog, ASightingAtARangeAtOrBelowZeroIsDroppedAndListed) {
  // MRPT's simul-landmarks adds Gaussian noise to the true range: a landmark next to the sensor now
  // and then comes out at a negative range. The log is read; that sighting alone is dropped, named.
  const auto path = write("near.rawlog", false, action(0.5, 0.0, 0.1), frame(bearing({{1, 2.0f}, {2, -0.03f}, {3, 1.0f}})),
                          action(0.5, 0.0, 0.1), frame(bearing({{2, 0.0f}})));
  const auto data = read_rawlog_2d(path);
  ASSERT_EQ(data.steps.size(), 2u);
  ASSERT_EQ(data.steps[0].observations.size(), 2u);
  EXPECT_EQ(data.steps[0].observations[0].landmark_id, 1u);
  EXPECT_EQ(data.steps[0].observations[1].landmark_id, 3u);
  EXPECT_TRUE(data.steps[1].observations.empty());
  EXPECT_EQ(data.implausible.count, 2u);
  const auto warnings = data.implausible.warnings();
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find(path + ": entry 1: landmark 2: range -0.03 m is not positive: the sighting is dropped"),
            std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[1].find("entry 3: landmark 2: range 0 m"), std::string::npos) << warnings[1];
  EXPECT_EQ(std::get<RawlogDataset2D>(read_rawlog(path)).implausible.count, 2u);
}

TEST_F(WrittenRawlog, LandmarksWithoutIdsTakeTheirIdsFromTheGroundTruth) {
  // Two landmarks 1 m apart, seen from the origin and from 1 m further on: MRPT's landmarkID = -1.
  auto obs = [](float range, float yaw) {
    auto o = bearing({{-1, range}});
    o->sensedData[0].yaw = yaw;
    return o;
  };
  auto two = [&](float r1, float y1, float r2, float y2) {
    auto o = obs(r1, y1);
    o->sensedData.push_back(obs(r2, y2)->sensedData[0]);
    return o;
  };
  const float far = static_cast<float>(std::hypot(3.0, 1.0)), near = static_cast<float>(std::hypot(2.0, 1.0));
  const auto path = write("no_ids.rawlog", false, action(1.0, 0.0, 0.0), frame(two(3.0f, 0.0f, far, std::atan2(1.0f, 3.0f))),
                          action(1.0, 0.0, 0.0), frame(obs(near, std::atan2(1.0f, 2.0f))));
  auto data = read_rawlog_2d(path);
  EXPECT_EQ(data.ids, io::LandmarkIds::absent);
  ASSERT_EQ(data.steps.size(), 2u);
  EXPECT_EQ(data.steps[0].observations[0].landmark_id, io::kNoLandmarkId);
  const auto map = (dir / "map.txt").string(), robot_path = (dir / "path.txt").string();
  std::ofstream(map) << "% x y z a b c id\n4 0 0 5 0 0 7\n4 1 0 5 0 0 9\n";
  std::ofstream(robot_path) << "0 0 0 0 0 0\n1 0 0 0 0 0\n2 0 0 0 0 0\n";
  const auto inferred = attach_ground_truth(data, {map, robot_path});
  ASSERT_TRUE(inferred);
  EXPECT_EQ(data.ids, io::LandmarkIds::from_ground_truth);
  EXPECT_EQ(inferred->observations, 3u);
  EXPECT_EQ(data.steps[0].observations[0].landmark_id, 7u);
  EXPECT_EQ(data.steps[0].observations[1].landmark_id, 9u);
  EXPECT_EQ(data.steps[1].observations[0].landmark_id, 9u);
  EXPECT_LT(inferred->worst_nis, 1e-6);  // measurements written exactly (floats)
  EXPECT_EQ(inferred->resolved_jointly, 0u);
  // One frame, two sightings nearest to landmark 7 each on its own: one exactly at it, one 0.4 m
  // towards 9. A sensor sees a landmark once a frame, so the second is 9's (the least total NIS).
  const float between = static_cast<float>(std::hypot(3.0, 0.4));
  const auto competing = write("competing.rawlog", false, action(1.0, 0.0, 0.0),
                               frame(two(3.0f, 0.0f, between, std::atan2(0.4f, 3.0f))));
  auto both = read_rawlog_2d(competing);
  const auto resolved = attach_ground_truth(both, {map, robot_path});
  ASSERT_TRUE(resolved);
  EXPECT_EQ(both.steps[0].observations[0].landmark_id, 7u);
  EXPECT_EQ(both.steps[0].observations[1].landmark_id, 9u);
  EXPECT_EQ(resolved->resolved_jointly, 1u);
  // Three sightings in a frame of a two-landmark world: one landmark was seen twice.
  auto three = two(3.0f, 0.0f, between, std::atan2(0.4f, 3.0f));
  three->sensedData.push_back(obs(far, std::atan2(1.0f, 3.0f))->sensedData[0]);
  auto crowded = read_rawlog_2d(write("crowded.rawlog", false, action(1.0, 0.0, 0.0), frame(three)));
  try {
    attach_ground_truth(crowded, {map, robot_path});
    ADD_FAILURE() << "three sightings took ids from two landmarks";
  } catch (const invalid_input_error& e) {
    EXPECT_NE(std::string(e.what()).find("step 0: more observations than true landmarks"), std::string::npos) << e.what();
  }
  // A log with ids is left as it is.
  const auto with_ids = write("ids.rawlog", false, action(1.0, 0.0, 0.0), frame(bearing({{7, 3.0f}})));
  auto known = read_rawlog_2d(with_ids);
  EXPECT_EQ(known.ids, io::LandmarkIds::measured);
}

// Fuzz findings 3 to 5 (docs/reliability.md): a corrupt length field makes MRPT's deserializer
// ask for gigabytes. This binary's operator new throws std::bad_alloc above 256 MiB
// (support/bounded_mrpt_alloc.hpp: so does MRPT's aligned_malloc), as they do on a machine without
// that memory, so the test never asks
// the system for it; the reader must turn it into a one-line parse_error.
class CorruptLengthField : public WrittenRawlog {
 protected:
  /// Writes a log, overwrites the 4-byte field holding `field` (which must occur exactly once)
  /// with `value` and returns the reader's error.
  template <class... Objects>
  std::string error_after_corrupting(std::uint32_t field, std::uint32_t value, const Objects&... objects) {
    const std::string pattern(reinterpret_cast<const char*>(&field), sizeof field);
    bool once = false;
    const auto corrupt = edited_copy(write("long.rawlog", true, objects...), "corrupt.rawlog", [&](std::string& bytes) {
      const auto at = bytes.find(pattern);
      once = at != std::string::npos && bytes.find(pattern, at + 1) == std::string::npos;
      if (once) bytes.replace(at, sizeof value, reinterpret_cast<const char*>(&value), sizeof value);
    });
    if (!once) {
      ADD_FAILURE() << "the field " << field << " does not occur exactly once in the log";
      return {};
    }
    return error_of(corrupt);
  }
  void expect_malformed_entry_1(const std::string& message) {
    EXPECT_NE(message.find((dir / "corrupt.rawlog").string() + ": entry 1: truncated or malformed"), std::string::npos)
        << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
};

TEST_F(CorruptLengthField, MeasurementCountIsAMalformedLogNotACrash) {
  constexpr std::uint32_t kCount = 2827;  // measurements: a length field that occurs nowhere else in the log
  std::vector<std::pair<int, float>> many;
  for (std::uint32_t i = 0; i < kCount; ++i) many.push_back({static_cast<int>(i), 2.0f});  // ids below kCount
  expect_malformed_entry_1(error_after_corrupting(kCount, 0x7fffffff, action(0.5, 0.0, 0.1), frame(bearing(many))));
}

TEST_F(CorruptLengthField, ObservationCountOfAFrameIsAMalformedLogNotACrash) {
  // A second finding of 2026-11-23: MRPT resizes the frame's std::deque of observations to the
  // count it reads, in small chunks no single-request bound catches (bounded_new.hpp's total bound).
  constexpr std::uint32_t kObservations = 1999;
  auto sf = ::mrpt::obs::CSensoryFrame::Create();
  for (std::uint32_t i = 0; i < kObservations; ++i) sf->insert(bearing({{static_cast<int>(i), 2.0f}}));
  expect_malformed_entry_1(error_after_corrupting(kObservations, 0x7fffffff, action(0.5, 0.0, 0.1), sf));
}

TEST_F(CorruptLengthField, StringLengthIsAMalformedLogNotACrash) {
  // The CI finding: the length of the observation's sensor label set to 1061109568.
  const std::string label = "a label of thirty-nine characters, odd.";
  auto observation = bearing({{1, 2.0f}});
  observation->sensorLabel = label;
  expect_malformed_entry_1(error_after_corrupting(static_cast<std::uint32_t>(label.size()), 1061109568u,
                                                  action(0.5, 0.0, 0.1), frame(observation)));
}

TEST_F(CorruptLengthField, VelocityCountOfASpatialActionIsAMalformedLogNotACrash) {
  // Finding 6 (CI 2026-11-23): CActionRobotMovement3D's velocities (a CVectorFloat, allocated
  // through mrpt::aligned_malloc, not new) resized to a corrupt length: 15.9 GB asked of aligned_alloc.
  constexpr std::uint32_t kVelocities = 2827;
  ::mrpt::obs::CActionRobotMovement3D move;
  move.velocities.resize(kVelocities);
  move.velocities.fill(0.0f);
  auto actions = ::mrpt::obs::CActionCollection::Create();
  actions->insert(move);
  expect_malformed_entry_1(error_after_corrupting(kVelocities, 0x7fffffff, frame(bearing({{1, 2.0f}})), actions));
}

TEST_F(WrittenRawlog, GroundTruthMustCoverEveryStepAndLandmark) {
  const auto path = write("gt.rawlog", false, action(0.5, 0.0, 0.1), frame(bearing({{1, 2.0f}})),
                          action(0.5, 0.0, 0.1), frame(bearing({{2, 2.0f}})));
  auto data = read_rawlog_2d(path);
  const auto map = (dir / "map.txt").string(), short_path = (dir / "path.txt").string();
  std::ofstream(map) << "% x y z a b c id\n1 2 0 5 0 0 1\n";
  std::ofstream(short_path) << "0 0 0 0 0 0\n0.5 0 0 0.1 0 0\n";
  try {
    attach_ground_truth(data, {map, short_path});
    FAIL() << "a path shorter than the steps was accepted";
  } catch (const parse_error& e) {
    EXPECT_NE(std::string(e.what()).find("2 poses for 2 steps"), std::string::npos) << e.what();
  }
  std::ofstream(short_path, std::ios::app) << "1 0 0 0.2 0 0\n";
  try {
    attach_ground_truth(data, {map, short_path});
    FAIL() << "a map without an observed landmark was accepted";
  } catch (const parse_error& e) {
    EXPECT_NE(std::string(e.what()).find("no ground truth for observed landmark 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sextant::mrpt_io
