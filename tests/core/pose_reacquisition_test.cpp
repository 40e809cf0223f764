// PoseReacquisition (core/pose_reacquisition.hpp): the offset that the rejected sightings of a lost
// pose agree on, the drift test, the rules of the record, and the probation's copy of its candidate;
// LostPoseRecovery (core/lost_pose_recovery.hpp) around a filter reduced to what it asks of one.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "sextant/core/lost_pose_recovery.hpp"
#include "sextant/core/pose_reacquisition.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/se2_world_frame.hpp"

namespace sextant {
namespace {

using Sensor = SeenInWorldFrame<RangeBearing2D>;
using Reacquisition = PoseReacquisition<Se2WorldSpace, Sensor, Eigen::Vector3d, 3>;
using Sighting = Reacquisition::Sighting;

Sensor range_bearing() {
  RangeBearing2D model;
  model.Q = Eigen::Vector2d(0.1 * 0.1, 0.01 * 0.01).asDiagonal();
  return Sensor(model);
}

/// Six sightings of three landmarks from a dead-reckoned path whose every pose is off by the same
/// world offset `lost_by` (the true pose is plus(x_i, lost_by)), measured exactly from the truth.
std::vector<Sighting> sightings_of_a_pose_lost_by(const Eigen::Vector3d& lost_by) {
  const Sensor sensor = range_bearing();
  const std::vector<Eigen::Vector2d> landmarks = {{4.0, 1.0}, {1.0, 5.0}, {-3.0, 2.0}};
  std::vector<Sighting> out;
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d estimate(0.3 * i, 0.1 * i, 0.2 * i);
    const Eigen::Vector2d& m = landmarks[static_cast<std::size_t>(i % 3)];
    const Eigen::Vector2d z = sensor.predict(Se2WorldSpace::plus(estimate, lost_by), m).z;
    out.push_back({static_cast<LandmarkId>(i % 3), estimate, m, z, sensor.Q});
  }
  return out;
}

Reacquisition after_a_long_drift() {
  Reacquisition test({.min_landmarks = 3}, 0.9999);
  test.set_drift(Eigen::Vector3d(1.0, 1.0, 0.5).asDiagonal());  // dead reckoning's spread since the last fix
  return test;
}

TEST(PoseReacquisition, FindsTheOffsetTheDeadReckonedPosesShare) {
  const Eigen::Vector3d lost_by(0.4, -0.3, 0.8);
  Reacquisition test = after_a_long_drift();
  const auto d = test.add_rejected(sightings_of_a_pose_lost_by(lost_by), range_bearing());
  ASSERT_TRUE(d.has_value());
  EXPECT_LT((*d - lost_by).norm(), 1e-6) << d->transpose();
  EXPECT_TRUE(test.record().empty()) << "the sightings a hypothesis was made of are not used twice";
}

TEST(PoseReacquisition, WaitsForEnoughDistinctLandmarks) {
  Reacquisition test = after_a_long_drift();
  auto sightings = sightings_of_a_pose_lost_by(Eigen::Vector3d(0.4, -0.3, 0.8));
  std::erase_if(sightings, [](const Sighting& s) { return s.id == 2; });  // four sightings, two landmarks
  EXPECT_FALSE(test.add_rejected(sightings, range_bearing()).has_value());
  EXPECT_EQ(test.record().size(), 4u);
}

/// A burst of outliers, each turned and stretched its own way, is explained by no single offset.
TEST(PoseReacquisition, SightingsNoOneOffsetExplainsAreOutliers) {
  auto sightings = sightings_of_a_pose_lost_by(Eigen::Vector3d::Zero());
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> turn(-1.5, 1.5), stretch(0.6, 1.5);
  for (auto& s : sightings) {
    s.z(0) *= stretch(rng);
    s.z(1) = wrap_angle(s.z(1) + turn(rng));
  }
  Reacquisition test = after_a_long_drift();
  EXPECT_FALSE(test.add_rejected(sightings, range_bearing()).has_value());
}

/// The same consistent sightings right after a fix: dead reckoning cannot have drifted that far.
TEST(PoseReacquisition, AnOffsetDeadReckoningCannotReachIsNotALostPose) {
  const Eigen::Vector3d lost_by(0.4, -0.3, 0.8);
  Reacquisition test({.min_landmarks = 3, .drift_factor = 5.0}, 0.9999);
  test.set_drift(Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal());
  EXPECT_FALSE(test.add_rejected(sightings_of_a_pose_lost_by(lost_by), range_bearing()).has_value());
  // The bound is d^T (c^2 D)^-1 d <= chi2(3, p): a drift D = d d^T / (c^2 q) + eps I sits on it.
  const double q = chi_square_quantile(3, 0.9999);
  test.set_drift(lost_by * lost_by.transpose() / (25.0 * q * 0.99) + 1e-9 * Eigen::Matrix3d::Identity());
  EXPECT_TRUE(test.plausible_drift(lost_by));
  test.set_drift(lost_by * lost_by.transpose() / (25.0 * q * 1.01) + 1e-9 * Eigen::Matrix3d::Identity());
  EXPECT_FALSE(test.plausible_drift(lost_by));
  test.accepted();
  EXPECT_FALSE(test.plausible_drift(lost_by)) << "no motion since a fix: no drift at all";
}

TEST(PoseReacquisition, OffRecordsNothingAndBadOptionsAreNamed) {
  Reacquisition off;
  EXPECT_FALSE(off.on());
  EXPECT_FALSE(off.add_rejected(sightings_of_a_pose_lost_by(Eigen::Vector3d(0.4, -0.3, 0.8)), range_bearing()));
  EXPECT_TRUE(off.record().empty());
  EXPECT_THROW(Reacquisition({.min_landmarks = -1}, 0.99), invalid_input_error);
  EXPECT_THROW(Reacquisition({.drift_factor = 0.0}, 0.99), invalid_input_error);
  EXPECT_THROW(Reacquisition({.probation = 0}, 0.99), invalid_input_error);
  EXPECT_THROW(Reacquisition({.min_landmarks = 3}, 0.0), invalid_input_error) << "needs the gate";
}

TEST(PoseProbation, CopiesItsCandidateAndKeepsTheHypothesisThatExplainsTheSightingsBetter) {
  PoseProbation<std::vector<int>> probation;
  EXPECT_FALSE(probation.active());
  probation.start(std::make_unique<std::vector<int>>(3, 7));
  PoseProbation<std::vector<int>> copy = probation;
  copy.candidate().push_back(1);
  EXPECT_EQ(probation.candidate().size(), 3u) << "a copy owns its own candidate";
  EXPECT_FALSE(probation.count(3, -20.0, -12.0, 5));  // 3 sightings seen, the candidate explains them better
  EXPECT_TRUE(probation.count(2, -4.0, -9.0, 5));     // 5 seen: -24 against -21
  EXPECT_TRUE(probation.candidate_won());
  EXPECT_FALSE(copy.count(5, -7.0, -7.0, 5) && copy.candidate_won()) << "a tie keeps the filter";
  EXPECT_EQ(probation.release()->size(), 3u);
  EXPECT_FALSE(probation.active());
}

/// What LostPoseRecovery asks of a back-end, and no more: its rejections are six sightings of a pose
/// lost by (0.4, -0.3, 0.2) (or reading them fails, as SEIF's marginals can), its update reports a
/// fixed likelihood, which the moved copy betters.
struct FilterReducedToItsHooks {
  using Recovery = LostPoseRecovery<FilterReducedToItsHooks, Reacquisition>;
  using Observations = std::span<const Observation<Eigen::Vector2d>>;
  Sensor sensor_ = range_bearing();
  Recovery recovery_;
  bool marginals_fail = false;
  Eigen::Vector3d moved_by = Eigen::Vector3d::Zero();
  double log_likelihood = -10.0;

  std::vector<Sighting> rejected_sightings(Observations, const UpdateResult&) const {
    if (marginals_fail) throw numerical_error("the rejected sightings' marginals cannot be read");
    return sightings_of_a_pose_lost_by(Eigen::Vector3d(0.4, -0.3, 0.2));
  }
  void reacquire_pose(const Eigen::Vector3d& d) {
    moved_by = d;
    log_likelihood = -1.0;
  }
  UpdateResult update(Observations) const { return {.corrected = 20, .log_likelihood = log_likelihood}; }
};

/// An update that rejected everything starts the probation of a copy moved by the offset the
/// rejections agree on; the copy explains the next 20 sightings better and follow_up hands it over,
/// with result.pose_reacquired. Where the rejections cannot be read, the attempt is skipped: no
/// throw out of follow_up (it is noexcept, so a throw would end the program), no probation.
TEST(LostPoseRecovery, HandsOverTheMovedCopyThatExplainsTheSightingsBetterAndSkipsAnAttemptItCannotMake) {
  const std::vector<Observation<Eigen::Vector2d>> none;
  for (const bool fail : {false, true}) {
    FilterReducedToItsHooks filter{.recovery_ = {{.min_landmarks = 3}, 0.9999}, .marginals_fail = fail};
    filter.recovery_.set_drift(Eigen::Vector3d(1.0, 1.0, 0.5).asDiagonal());
    UpdateResult all_rejected{.rejected = {0, 1, 2}, .log_likelihood = -30.0};
    EXPECT_EQ(filter.recovery_.follow_up(filter, std::span(none), all_rejected), nullptr);
    UpdateResult next = filter.update(none);
    const auto winner = filter.recovery_.follow_up(filter, std::span(none), next);
    EXPECT_EQ(winner != nullptr, !fail);
    EXPECT_EQ(next.pose_reacquired, !fail);
    if (winner) EXPECT_LT((winner->moved_by - Eigen::Vector3d(0.4, -0.3, 0.2)).norm(), 1e-6);
    EXPECT_EQ(filter.moved_by, Eigen::Vector3d::Zero()) << "the filter itself is never moved by follow_up";
  }
}

}  // namespace
}  // namespace sextant
