// EKF- and SEIF-SLAM of a planar robot with the pose perturbed in the world frame and first-estimate
// Jacobians (models/se2_world_frame.hpp, EkfOptions/SeifOptions::first_estimate_jacobians) against
// the textbook filters on the same run: the global heading of planar SLAM is unobservable, so no
// filter may know the robot's heading better than its prior does.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <array>
#include <numbers>
#include <map>
#include <random>
#include <set>

#include "../support/shared_data.hpp"
#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/core/landmark_init.hpp"
#include "sextant/eval/alignment.hpp"
#include "sextant/eval/dead_reckoning.hpp"
#include "sextant/eval/metrics.hpp"
#include "sextant/io/isam_dataset.hpp"
#include "sextant/io/mrclam_reader.hpp"
#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/se2_odometry.hpp"
#include "sextant/models/se2_world_frame.hpp"
#include "sextant/models/unicycle.hpp"

namespace sextant {
namespace {

/// A robot circling (radius 6 m) inside a ring of 24 landmarks (radius 10 m), seeing those within
/// 7 m with range-bearing noise; the filter's controls carry the unicycle's noise.
struct CircleRun {
  Unicycle motion{.alpha = {0.02, 0.002, 0.02, 0.05, 0.0, 0.001}};
  RangeBearing2D sensor;
  Gaussian<Eigen::Vector3d, 3> prior{Eigen::Vector3d(6.0, 0.0, std::numbers::pi / 2),
                                     Eigen::Vector3d(1e-2, 1e-2, 1e-2).asDiagonal()};
  std::vector<Eigen::Vector2d> landmarks;
  std::vector<UnicycleControl> controls;
  std::vector<std::vector<Observation<Eigen::Vector2d>>> observations;
  std::vector<Eigen::Vector3d> truth;  ///< the robot's pose after each step
  static constexpr double dt = 0.1;

  explicit CircleRun(std::uint64_t seed) {
    sensor.Q = Eigen::Vector2d(0.1 * 0.1, 0.01 * 0.01).asDiagonal();
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> unit(0.0, 1.0);
    for (int j = 0; j < 24; ++j) {
      const double a = 2.0 * std::numbers::pi * j / 24;
      landmarks.emplace_back(10.0 * std::cos(a), 10.0 * std::sin(a));
    }
    Eigen::Vector3d x = prior.mean;
    const UnicycleControl truth{1.0, 1.0 / 6.0};
    for (int k = 0; k < 800; ++k) {
      const Eigen::Matrix2d vw_noise = Eigen::Vector2d(0.03, 0.01).asDiagonal();
      const Eigen::Vector2d e = vw_noise * Eigen::Vector2d(unit(rng), unit(rng));
      controls.push_back({truth.v + e(0), truth.w + e(1)});
      x = motion.predict(x, truth, dt).x;
      this->truth.push_back(x);
      std::vector<Observation<Eigen::Vector2d>> seen;
      for (std::size_t j = 0; j < landmarks.size(); ++j) {
        if ((landmarks[j] - x.head<2>()).norm() > 7.0) continue;
        Eigen::Vector2d z = sensor.predict(x, landmarks[j]).z;
        z += Eigen::Vector2d(0.1 * unit(rng), 0.01 * unit(rng));
        seen.push_back({static_cast<LandmarkId>(j), z});
      }
      observations.push_back(std::move(seen));
    }
  }

  /// Runs the filter over the data; returns each landmark's first estimate (its mean right after the
  /// update that added it).
  template <class Filter>
  std::map<LandmarkId, Eigen::Vector2d> run(Filter& filter) const {
    std::map<LandmarkId, Eigen::Vector2d> first;
    for (std::size_t k = 0; k < controls.size(); ++k) {
      filter.predict(controls[k], dt);
      filter.update(observations[k]);
      for (LandmarkId id : filter.landmark_ids()) first.try_emplace(id, filter.landmark(id).mean);
    }
    return first;
  }

  /// Runs SEIF over the data; returns each landmark's first estimate, which SEIF takes at the pose
  /// predicted before the update that adds it (thesis eqs. 27-30; the EKF takes the corrected one).
  template <class Seif, class Sensor>
  std::map<LandmarkId, Eigen::Vector2d> run_seif(Seif& seif, const Sensor& seif_sensor) const {
    std::map<LandmarkId, Eigen::Vector2d> first;
    for (std::size_t k = 0; k < controls.size(); ++k) {
      seif.predict(controls[k], dt);
      const auto predicted = seif.pose().mean;
      seif.update(observations[k]);
      for (const auto& observation : observations[k])
        if (!first.contains(observation.landmark_id))
          first.emplace(observation.landmark_id,
                        initialize_landmark(seif_sensor, predicted, observation.z, observation.landmark_id, 1.0).m);
    }
    return first;
  }
};

/// The global rotation N in the filter's state: the robot's heading and each landmark by J m, plus,
/// in the additive chart, the robot's position by J p.
template <class Filter>
Eigen::VectorXd global_rotation(const Filter& filter, const std::map<LandmarkId, Eigen::Vector2d>& landmark_at,
                                bool additive_chart) {
  Eigen::Matrix2d J;
  J << 0, -1, 1, 0;
  Eigen::VectorXd N = Eigen::VectorXd::Zero(filter.state_dim());
  if (additive_chart) N.head<2>() = J * filter.pose().mean.template head<2>();
  N(2) = 1.0;
  const auto& ids = filter.landmark_ids();
  for (std::size_t slot = 0; slot < ids.size(); ++slot) N.segment<2>(3 + 2 * static_cast<Eigen::Index>(slot)) = J * landmark_at.at(ids[slot]);
  return N;
}

/// N^T P^-1 N of a filter in moment form.
template <class Filter>
double information_along_global_rotation(const Filter& filter, const std::map<LandmarkId, Eigen::Vector2d>& landmark_at,
                                         bool additive_chart) {
  const Eigen::VectorXd N = global_rotation(filter, landmark_at, additive_chart);
  return N.dot(filter.covariance().ldlt().solve(N));
}

/// The world-chart EKF with first estimates against the textbook EKF (the peer) on the same data:
/// `run(filter)` runs a filter over the data and returns each landmark's first estimate. Theory: with
/// the motion Jacobian I and every H annihilating N at the landmarks' first estimates, predictions
/// only add noise along N and updates add none, so the information along the unobservable global
/// rotation can only fall from the prior's. The margin 1e-6 (relative) is rounding. The textbook
/// EKF, linearized at its current estimates, ends above the same bound (along N at its estimates):
/// the first check can fail. Returns both informations and the prior's.
template <class Motion, class Sensor, class Run>
std::array<double, 3> expect_only_the_textbook_ekf_gains_heading_information(const Motion& motion, const Sensor& sensor,
                                                                              const Gaussian<Eigen::Vector3d, 3>& prior,
                                                                              Run run) {
  EkfSlam<InWorldFrame<Motion>, SeenInWorldFrame<Sensor>> consistent(
      InWorldFrame<Motion>(motion), SeenInWorldFrame<Sensor>(sensor), in_world_frame(prior), {.first_estimate_jacobians = true});
  EkfSlam<Motion, Sensor> textbook(motion, sensor, prior);
  const double prior_information = in_world_frame(prior).cov.inverse()(2, 2);
  const auto first = run(consistent);
  const double world = information_along_global_rotation(consistent, first, false);
  EXPECT_LE(world, prior_information * (1.0 + 1e-6));
  run(textbook);
  std::map<LandmarkId, Eigen::Vector2d> current;
  for (const auto& landmark : textbook.map()) current.emplace(landmark.id, landmark.mean);
  const double additive = information_along_global_rotation(textbook, current, true);
  EXPECT_GT(additive, prior_information * (1.0 + 1e-6));
  return {world, additive, prior_information};
}

/// The circle run; at the prior's pose (6, 0) its additive covariance diag(1e-2) gives the bound
/// (6^2 + 1) / 1e-2.
TEST(PlanarFirstEstimates, WorldFrameEkfGainsNoInformationAboutTheGlobalHeading) {
  const CircleRun data(7);
  expect_only_the_textbook_ekf_gains_heading_information(data.motion, data.sensor, data.prior,
                                                         [&](auto& filter) { return data.run(filter); });
}

/// The same bound for SEIF with first estimates, read off its information matrix: N^T Omega N. Without
/// sparsification SEIF is the EKF in information form, so the theory above holds unchanged, with N
/// at SEIF's own first estimates: a new landmark's conditional m = init.m + J_m_x dx + v adds
/// information that annihilates N only when N's landmark block is J init.m. The textbook SEIF
/// (Jacobians at current estimates, additive chart) is the peer that ends above the bound.
TEST(PlanarFirstEstimates, WorldFrameSeifGainsNoInformationAboutTheGlobalHeading) {
  const CircleRun data(7);
  using WorldMotion = InWorldFrame<Unicycle>;
  using WorldSensor = SeenInWorldFrame<RangeBearing2D>;
  SeifSlam<WorldMotion, WorldSensor> consistent(
      WorldMotion(data.motion), WorldSensor(data.sensor), in_world_frame(data.prior),
      {.max_active = 0, .exact_recovery_period = 1, .first_estimate_jacobians = true});
  SeifSlam<Unicycle, RangeBearing2D> textbook(data.motion, data.sensor, data.prior,
                                              {.max_active = 0, .exact_recovery_period = 1});
  const double prior_information = in_world_frame(data.prior).cov.inverse()(2, 2);
  const auto first = data.run_seif(consistent, WorldSensor(data.sensor));
  const Eigen::VectorXd N = global_rotation(consistent, first, false);
  EXPECT_LE(N.dot(consistent.information_matrix() * N), prior_information * (1.0 + 1e-6));
  data.run(textbook);
  std::map<LandmarkId, Eigen::Vector2d> current;
  for (const auto& landmark : textbook.map()) current.emplace(landmark.id, landmark.mean);
  const Eigen::VectorXd N_textbook = global_rotation(textbook, current, true);
  EXPECT_GT(N_textbook.dot(textbook.information_matrix() * N_textbook), prior_information * (1.0 + 1e-6));
}

/// Runs a filter over a data set's steps; returns each landmark's first estimate (its mean right
/// after the update that added it).
template <class Filter, class Dataset>
std::map<LandmarkId, Eigen::Vector2d> run_recording_first_estimates(Filter& filter, const Dataset& data) {
  std::map<LandmarkId, Eigen::Vector2d> first;
  for (const auto& step : data.steps) {
    filter.predict(step.control, step.dt);
    filter.update(step.observations);
    for (LandmarkId id : filter.landmark_ids()) first.try_emplace(id, filter.landmark(id).mean);
  }
  return first;
}

/// The same theory on a data set the chart was not built for: cityTrees10000 (iSAM text: SE(2)
/// odometry with each record's noise, trees as points in the robot frame, 9999 steps, 100 trees),
/// as sextant-run runs its filters ([isam] filters_in_world_frame). The world-chart EKF with first
/// estimates ends with no more information along the global rotation than its prior's (the margin
/// 1e-6 relative is rounding, as above); the textbook EKF on the same steps, the peer, ends above it.
/// The start pose's standard deviation is 0.1 (m, rad) here, not the runner's 1e-3: the bound holds
/// for any prior, and against a prior that tight the textbook's spurious information would stay
/// below it after the process noise of 9999 steps, and the check on the peer could not fail.
TEST(PlanarFirstEstimates, OnCityTreesTheWorldFrameEkfGainsNoInformationAboutTheGlobalHeading) {
  const std::string path = test::shared_data("city_trees/cityTrees10000.txt");
  SEXTANT_REQUIRE_DATA(path);
  const auto data = io::read_isam_dataset(path, std::nullopt, 0.1);
  const auto [world, additive, prior] = expect_only_the_textbook_ekf_gains_heading_information(
      data.motion, data.sensor, data.prior, [&](auto& filter) { return run_recording_first_estimates(filter, data); });
  std::printf("cityTrees10000: information along the global rotation %.6g (world chart, first estimates), %.6g "
              "(textbook); the prior's %.6g\n",
              world, additive, prior);
}

/// Root mean square of the position error of a filter run over the steps, against Vicon.
template <class Filter>
double position_rmse(Filter& filter, const io::MrclamRun& data) {
  double sum = 0.0;
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    filter.predict(data.steps[k].control, data.steps[k].dt);
    filter.update(data.steps[k].observations);
    sum += (filter.pose().mean.template head<2>() - data.true_poses[k + 1].head<2>()).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(data.steps.size()));
}

/// Root mean square of dead reckoning's position error over the steps, against Vicon.
double dead_reckoning_rmse(const io::MrclamRun& data) {
  const auto drift = eval::dead_reckoning(data.motion, data.prior.mean, data.steps);
  double sum = 0.0;
  for (std::size_t k = 0; k < drift.size(); ++k) sum += (drift[k].head<2>() - data.true_poses[k + 1].head<2>()).squaredNorm();
  return std::sqrt(sum / static_cast<double>(drift.size()));
}

/// On real data (MRCLAM Dataset6, odometry 0.2 s late as measured, 0.9999 gate against its bearing
/// outliers): the world-chart EKF with first estimates stays below half of dead reckoning's RMSE on
/// every robot (issue 14's bound) and below the textbook EKF with the same gate (the peer). Measured
/// 2026-11-24: 0.28-0.45 m, dead reckoning 1.7-4.2 m, textbook 0.34-1.53 m (docs/results/mrclam.md).
TEST(PlanarFirstEstimates, OnMrclamTheWorldFrameEkfBeatsHalfOfDeadReckoningAndTheTextbookEkf) {
  const std::string dir = test::shared_data("mrclam/MRCLAM_Dataset6");
  SEXTANT_REQUIRE_DATA(dir);
  using WorldMotion = InWorldFrame<Unicycle>;
  using WorldSensor = SeenInWorldFrame<RangeBearing2D>;
  for (int robot = 1; robot <= 5; ++robot) {
    const auto data = io::read_mrclam(dir, robot, {.odometry_delay = 0.2});
    const double dead_reckoning = dead_reckoning_rmse(data);
    EkfSlam<WorldMotion, WorldSensor> world(WorldMotion(data.motion), WorldSensor(data.sensor), in_world_frame(data.prior),
                                            {.gate_probability = 0.9999, .first_estimate_jacobians = true});
    EkfSlam<Unicycle, RangeBearing2D> textbook(data.motion, data.sensor, data.prior, {.gate_probability = 0.9999});
    const double world_rmse = position_rmse(world, data), textbook_rmse = position_rmse(textbook, data);
    EXPECT_LT(world_rmse, 0.5 * dead_reckoning) << "robot " << robot;
    EXPECT_LT(world_rmse, textbook_rmse) << "robot " << robot;
  }
}

/// SEIF as sextant-run runs it on MRCLAM (8 active landmarks, 0.9999 gate, world chart, first
/// estimates) stays below half of dead reckoning's RMSE on every robot, issue 14's bound. Measured
/// 2026-11-25: 0.28-0.63 m; without first estimates robots 4 and 5 were above it (1.25, 1.08 m).
TEST(PlanarFirstEstimates, OnMrclamTheWorldFrameSeifBeatsHalfOfDeadReckoning) {
  const std::string dir = test::shared_data("mrclam/MRCLAM_Dataset6");
  SEXTANT_REQUIRE_DATA(dir);
  using WorldMotion = InWorldFrame<Unicycle>;
  using WorldSensor = SeenInWorldFrame<RangeBearing2D>;
  for (int robot = 1; robot <= 5; ++robot) {
    const auto data = io::read_mrclam(dir, robot, {.odometry_delay = 0.2});
    SeifSlam<WorldMotion, WorldSensor> seif(
        WorldMotion(data.motion), WorldSensor(data.sensor), in_world_frame(data.prior),
        {.max_active = 8, .gate_probability = 0.9999, .first_estimate_jacobians = true});
    EXPECT_LT(position_rmse(seif, data), 0.5 * dead_reckoning_rmse(data)) << "robot " << robot;
  }
}

/// What a stress run of the world-chart EKF reports: position RMSE after rigid alignment to Vicon
/// (aligned on the steps from `scored_from` seconds on, and scored on them), the updates that failed, and the smallest ratio
/// lambda_min(P) / lambda_max(P) over the steps.
struct StressRun {
  double aligned_rmse = 0.0;
  std::size_t failed_updates = 0;
  double worst_eigenvalue_ratio = 1.0;
};

/// A filter run over the data; a failed update is counted and the run goes on. `after_step` sees
/// the filter after each step.
template <class Filter, class AfterStep>
StressRun stress_run(Filter& filter, const io::MrclamRun& data, double scored_from, AfterStep after_step) {
  StressRun out;
  std::vector<Eigen::Vector2d> estimate, truth;
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    filter.predict(data.steps[k].control, data.steps[k].dt);
    try {
      filter.update(data.steps[k].observations);
    } catch (const error&) {
      ++out.failed_updates;
    }
    after_step(filter, out);
    if (data.step_times[k] < scored_from) continue;
    estimate.push_back(filter.pose().mean.template head<2>());
    truth.push_back(data.true_poses[k + 1].head<2>());
  }
  out.aligned_rmse = eval::rms(eval::aligned_errors<2>(estimate, truth));
  return out;
}

/// The EKF as sextant-run runs it on MRCLAM (world chart, first estimates, 0.9999 gate), with P's
/// spectrum checked after every step.
StressRun world_ekf_stress_run(const io::MrclamRun& data, double scored_from, bool reacquire = true) {
  using WorldMotion = InWorldFrame<Unicycle>;
  using WorldSensor = SeenInWorldFrame<RangeBearing2D>;
  EkfOptions options{.gate_probability = 0.9999, .first_estimate_jacobians = true};
  options.reacquisition.min_landmarks = reacquire ? 3 : 0;  // 3: as sextant-run's MRCLAM family
  EkfSlam<WorldMotion, WorldSensor> ekf(WorldMotion(data.motion), WorldSensor(data.sensor), in_world_frame(data.prior), options);
  return stress_run(ekf, data, scored_from, [](const auto& filter, StressRun& out) {
    const Eigen::VectorXd eigenvalues =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(filter.covariance(), Eigen::EigenvaluesOnly).eigenvalues();
    out.worst_eigenvalue_ratio = std::min(out.worst_eigenvalue_ratio, eigenvalues.minCoeff() / eigenvalues.maxCoeff());
  });
}

/// SEIF as sextant-run runs it on MRCLAM (8 active, world chart, first estimates, 0.9999 gate), with
/// the thesis's sparsification or ESEIF's relocalization.
StressRun world_seif_stress_run(const io::MrclamRun& data, double scored_from, bool reacquire,
                                SeifSparsification sparsification) {
  using WorldMotion = InWorldFrame<Unicycle>;
  using WorldSensor = SeenInWorldFrame<RangeBearing2D>;
  SeifOptions options{.max_active = 8, .sparsification = sparsification, .gate_probability = 0.9999,
                      .first_estimate_jacobians = true};
  options.reacquisition.min_landmarks = reacquire ? 3 : 0;
  SeifSlam<WorldMotion, WorldSensor> seif(WorldMotion(data.motion), WorldSensor(data.sensor), in_world_frame(data.prior), options);
  return stress_run(seif, data, scored_from, [](const auto&, StressRun&) {});
}

/// Issue 35's stress cases, built from Dataset6.
/// A burst of outliers: from `from` seconds on, the next `count` sightings turned by 1.5 rad and
/// 1.5 times as far.
io::MrclamRun with_outlier_burst(io::MrclamRun data, double from, int count) {
  for (std::size_t k = 0; k < data.steps.size() && count > 0; ++k) {
    if (data.step_times[k] < from) continue;
    for (auto& o : data.steps[k].observations) {
      if (count-- <= 0) break;
      o.z(0) *= 1.5;
      o.z(1) = wrap_angle(o.z(1) + 1.5);
    }
  }
  return data;
}
/// A long gap: no sightings from `from` to `to` seconds.
io::MrclamRun with_sightings_removed(io::MrclamRun data, double from, double to) {
  for (std::size_t k = 0; k < data.steps.size(); ++k)
    if (data.step_times[k] >= from && data.step_times[k] < to) data.steps[k].observations.clear();
  return data;
}
/// Wrong first estimates: every landmark's first sighting 0.5 m too far (over 3 of its range sigmas).
io::MrclamRun with_far_first_sightings(io::MrclamRun data) {
  std::set<LandmarkId> seen;
  for (auto& step : data.steps)
    for (auto& o : step.observations)
      if (seen.insert(o.landmark_id).second) o.z(0) += 0.5;
  return data;
}

/// The world-chart EKF on Dataset6 with a burst of 30 outliers, with wrong first estimates and with
/// a minute without sightings: no update fails, P stays positive semi-definite (lambda_min /
/// lambda_max above -1e-12: rounding), and the aligned position RMSE stays within 2x the clean
/// run's (issue 35's bound; after the gap scored from 30 s after it). Measured 2026-11-26: burst
/// 1.00-1.78x (robot 4), first estimates 0.92-1.10x, gap 1.09-1.38x with re-acquisition (without:
/// 2.61x, 9.89x and 8.70x on robots 1-3, the gate rejecting every returning sighting),
/// smallest eigenvalue ratio of P 2e-7.
TEST(PlanarFirstEstimates, OnMrclamTheWorldFrameEkfSurvivesOutlierBurstsWrongFirstEstimatesAndGaps) {
  const std::string dir = test::shared_data("mrclam/MRCLAM_Dataset6");
  SEXTANT_REQUIRE_DATA(dir);
  double worst_gap_without = 0.0;  // the gap's ratio without re-acquisition, the worst robot's
  for (int robot = 1; robot <= 5; ++robot) {
    const auto data = io::read_mrclam(dir, robot, {.odometry_delay = 0.2});
    struct Case {
      const char* name;
      io::MrclamRun data;
      double scored_from;
    };
    const Case cases[] = {{"a burst of 30 outliers", with_outlier_burst(data, 400.0, 30), 0.0},
                          {"first sightings 0.5 m too far", with_far_first_sightings(data), 0.0},
                          {"no sightings from 300 to 360 s", with_sightings_removed(data, 300.0, 360.0), 390.0}};
    for (const auto& c : cases) {
      const StressRun clean = world_ekf_stress_run(data, c.scored_from), run = world_ekf_stress_run(c.data, c.scored_from);
      EXPECT_EQ(run.failed_updates, 0u) << "robot " << robot << ", " << c.name;
      EXPECT_GT(run.worst_eigenvalue_ratio, -1e-12) << "robot " << robot << ", " << c.name;
      EXPECT_LE(run.aligned_rmse, 2.0 * clean.aligned_rmse) << "robot " << robot << ", " << c.name;
      std::printf("robot %d, %-30s aligned RMSE %.3f m, clean %.3f m (%.2fx); smallest eigenvalue ratio of P %.2e\n",
                  robot, c.name, run.aligned_rmse, clean.aligned_rmse, run.aligned_rmse / clean.aligned_rmse,
                  run.worst_eigenvalue_ratio);
    }
    const auto& gap = cases[2];
    worst_gap_without = std::max(worst_gap_without, world_ekf_stress_run(gap.data, gap.scored_from, false).aligned_rmse /
                                                        world_ekf_stress_run(data, gap.scored_from, false).aligned_rmse);
  }
  EXPECT_GT(worst_gap_without, 2.0) << "without re-acquisition the gap is a failure on some robot";
}

/// SEIF and ESEIF re-acquire a lost pose with the EKF's machinery (core/lost_pose_recovery.hpp): the
/// minute without sightings of the test above leaves each within 2x of its clean run on every robot
/// (issue 35's bound), where without re-acquisition the gate rejects the returning sightings and some
/// robot fails. Measured 2026-12-05: see the printout and docs/results/mrclam.md.
TEST(PlanarFirstEstimates, OnMrclamTheWorldFrameSeifReacquiresAPoseLostInAGap) {
  const std::string dir = test::shared_data("mrclam/MRCLAM_Dataset6");
  SEXTANT_REQUIRE_DATA(dir);
  for (const auto sparsification : {SeifSparsification::thesis, SeifSparsification::relocalization}) {
    const char* name = sparsification == SeifSparsification::thesis ? "SEIF" : "ESEIF";
    double worst_without = 0.0;
    for (int robot = 1; robot <= 5; ++robot) {
      const auto data = io::read_mrclam(dir, robot, {.odometry_delay = 0.2});
      const auto gap = with_sightings_removed(data, 300.0, 360.0);
      const StressRun clean = world_seif_stress_run(data, 390.0, true, sparsification),
                      run = world_seif_stress_run(gap, 390.0, true, sparsification);
      const double without = world_seif_stress_run(gap, 390.0, false, sparsification).aligned_rmse /
                             world_seif_stress_run(data, 390.0, false, sparsification).aligned_rmse;
      EXPECT_EQ(run.failed_updates, 0u) << name << ", robot " << robot;
      EXPECT_LE(run.aligned_rmse, 2.0 * clean.aligned_rmse) << name << ", robot " << robot;
      std::printf("robot %d: %s after the gap, aligned RMSE %.3f m, clean %.3f m (%.2fx; without re-acquisition %.2fx)\n",
                  robot, name, run.aligned_rmse, clean.aligned_rmse, run.aligned_rmse / clean.aligned_rmse, without);
      worst_without = std::max(worst_without, without);
    }
    EXPECT_GT(worst_without, 2.0) << name << ": without re-acquisition the gap is a failure on some robot";
  }
}

/// CircleRun with steps [from, to) without sightings, during which the odometry reports `bias`
/// rad/s more turn than the robot makes (a slipping wheel): the filter comes back with its heading
/// off by several of its own standard deviations.
CircleRun with_gap_and_heading_bias(CircleRun run, std::size_t from, std::size_t to, double bias) {
  for (std::size_t k = from; k < to; ++k) {
    run.observations[k].clear();
    run.controls[k].w += bias;
  }
  return run;
}

/// Mean position error over the steps from `scored_from` of the world-chart EKF as MRCLAM runs it
/// (0.9999 gate, first estimates), re-acquiring a lost pose after `min_landmarks` or never (0); the
/// number of re-acquisitions in `reacquired`.
double world_ekf_error_from(const CircleRun& run, std::size_t scored_from, int min_landmarks, int& reacquired) {
  using WorldMotion = InWorldFrame<Unicycle>;
  using WorldSensor = SeenInWorldFrame<RangeBearing2D>;
  EkfOptions options{.gate_probability = 0.9999, .first_estimate_jacobians = true};
  options.reacquisition.min_landmarks = min_landmarks;
  EkfSlam<WorldMotion, WorldSensor> ekf(WorldMotion(run.motion), WorldSensor(run.sensor), in_world_frame(run.prior), options);
  double sum = 0.0;
  reacquired = 0;
  for (std::size_t k = 0; k < run.controls.size(); ++k) {
    ekf.predict(run.controls[k], CircleRun::dt);
    reacquired += ekf.update(run.observations[k]).pose_reacquired ? 1 : 0;
    if (k >= scored_from) sum += (ekf.pose().mean.head<2>() - run.truth[k].head<2>()).norm();
  }
  return sum / static_cast<double>(run.controls.size() - scored_from);
}

/// Issue 35's long gap on the simulated circle: 20 s without sightings while the odometry turns
/// 0.06 rad/s too much (1.2 rad by the end, over 5 of the filter's heading sigmas). The gate then
/// rejects every returning sighting; the EKF that never re-acquires stays lost (its error is
/// asserted to be over 10x the clean run's: the failure is real), the default one re-acquires
/// and is within 2x of the clean run from 20 s after the gap on (issue 35's bound for stress
/// cases; the clean run re-acquires nothing). Measured 2026-11-26: clean 0.014 m, never 5.0 m,
/// re-acquired once, 0.013 m (0.038 m over the first 10 s after the gap).
TEST(PoseReacquisition, TheEkfReacquiresAPoseLostInALongGap) {
  const CircleRun clean(11);
  const CircleRun gap = with_gap_and_heading_bias(clean, 300, 500, 0.06);
  int reacquired_clean = 0, reacquired_never = 0, reacquired = 0;
  const std::size_t from = 700;  // 20 s after the gap (the MRCLAM case scores from 30 s after its gap)
  const double clean_error = world_ekf_error_from(clean, from, 3, reacquired_clean);
  const double never = world_ekf_error_from(gap, from, 0, reacquired_never);
  const double error = world_ekf_error_from(gap, from, 3, reacquired);
  std::printf("position error from step 700: clean %.3f m, lost and never re-acquired %.3f m, re-acquired %.3f m (%d times)\n",
              clean_error, never, error, reacquired);
  EXPECT_EQ(reacquired_clean, 0);
  EXPECT_GT(never, 10.0 * clean_error);
  EXPECT_GE(reacquired, 1);
  EXPECT_LE(error, 2.0 * clean_error);
}

/// Through the steps where the EKF tests a lost pose (a moved copy on probation beside it), an
/// update that throws (a range of 1e300 m) leaves everything as it was, the copy included: a filter
/// kept from before the throw (a deep copy) and the one that threw go on bit for bit alike.
TEST(PoseReacquisition, AnUpdateThatThrowsDuringTheProbationChangesNothing) {
  using WorldMotion = InWorldFrame<Unicycle>;
  using WorldSensor = SeenInWorldFrame<RangeBearing2D>;
  const CircleRun run = with_gap_and_heading_bias(CircleRun(11), 300, 500, 0.06);
  EkfOptions options{.gate_probability = 0.9999, .first_estimate_jacobians = true};
  options.reacquisition.min_landmarks = 3;
  EkfSlam<WorldMotion, WorldSensor> ekf(WorldMotion(run.motion), WorldSensor(run.sensor), in_world_frame(run.prior), options);
  int reacquired = 0;
  for (std::size_t k = 0; k < 560; ++k) {
    ekf.predict(run.controls[k], CircleRun::dt);
    if (k >= 500 && !run.observations[k].empty()) {
      const auto kept = ekf;
      auto absurd = run.observations[k];
      absurd.front().z(0) = 1e300;
      EXPECT_THROW(ekf.update(absurd), error) << "step " << k;
      EXPECT_EQ(ekf.pose().mean, kept.pose().mean);
      EXPECT_EQ(ekf.covariance(), kept.covariance());
      auto twin = kept;
      reacquired += ekf.update(run.observations[k]).pose_reacquired ? 1 : 0;
      twin.update(run.observations[k]);
      ASSERT_EQ(ekf.pose().mean, twin.pose().mean) << "step " << k;
      ASSERT_EQ(ekf.covariance(), twin.covariance()) << "step " << k;
    } else {
      ekf.update(run.observations[k]);
    }
  }
  EXPECT_GE(reacquired, 1) << "the steps tested include the end of a probation";
}

}  // namespace
}  // namespace sextant
