// The iterated EKF, SEIF and FastSLAM 2.0 proposal (EkfOptions::iterations, SeifOptions::iterations,
// FastSlamOptions::iterations) against the textbook
// update on one step where the linearization at the prediction fails: a landmark 5 cm from a sensor
// whose robot the odometry predicts to within 4 cm (MRPT's simul-landmarks logs have such steps:
// docs/results/iterated_ekf.md).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <iostream>
#include <vector>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/fast_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/se2_odometry.hpp"

namespace sextant {
namespace {

using Ekf = EkfSlam<Se2Odometry, RangeBearing2D>;
using Seif = SeifSlam<Se2Odometry, RangeBearing2D>;
using Sightings = std::vector<Observation<Eigen::Vector2d>>;

const std::vector<Eigen::Vector2d> kLandmarks{{0.30, 0.02}, {2.0, 1.0}, {1.0, -2.0}, {3.0, 0.5}};
const Eigen::Vector3d kTruthAfterMove(0.25, 0.03, 0.0);  // odometry says (0.2, 0, 0)

RangeBearing2D sensor() {
  RangeBearing2D out;
  out.Q = Eigen::Vector2d(0.01 * 0.01, 0.00175 * 0.00175).asDiagonal();  // 1 cm, 0.1 deg
  return out;
}

Sightings sightings_from(const Eigen::Vector3d& pose) {
  Sightings out;
  for (std::size_t i = 0; i < kLandmarks.size(); ++i)
    out.push_back({static_cast<LandmarkId>(i), sensor().predict(pose, kLandmarks[i]).z});
  return out;
}

const Ekf::PoseEstimate kExactStart{Eigen::Vector3d::Zero(), 1e-10 * Eigen::Matrix3d::Identity()};

/// The map from an exact start, then the odometry's step: 4 cm in x and y.
template <class Filter>
Filter before_the_update(Filter filter) {
  filter.update(sightings_from(Eigen::Vector3d::Zero()));
  filter.predict({Eigen::Vector3d(0.2, 0.0, 0.0), Eigen::Vector3d(0.04 * 0.04, 0.04 * 0.04, 1.75e-4 * 1.75e-4).asDiagonal()}, 1.0);
  return filter;
}

Ekf filter_before_the_update(int iterations) {
  return before_the_update(Ekf{Se2Odometry{}, sensor(), kExactStart, {.iterations = iterations}});
}

Eigen::VectorXd stacked_mean(const Ekf& ekf) {
  Eigen::VectorXd out(ekf.state_dim());
  out.head<3>() = ekf.pose().mean;
  for (std::size_t slot = 0; slot < ekf.num_landmarks(); ++slot)
    out.segment<2>(3 + 2 * slot) = ekf.landmark(ekf.landmark_ids()[slot]).mean;
  return out;
}

/// How far the update's mean x is from the optimum of ||x - x0||^2_P0^-1 + sum ||z - h(x)||^2_Q^-1:
/// the optimum has x - x0 = P0 H^T Q^-1 (z - h(x)) with H at x; relative to |x - x0|.
double distance_from_stationarity(const Ekf& before, const Ekf& after, const Sightings& sightings) {
  const Eigen::VectorXd x0 = stacked_mean(before), x = stacked_mean(after);
  Eigen::VectorXd step = x - x0;
  step(2) = wrap_angle(step(2));
  Eigen::VectorXd weighted_gradient = Eigen::VectorXd::Zero(x.size());  // H^T Q^-1 (z - h(x))
  const auto model = sensor();
  for (const auto& sighting : sightings) {
    const Eigen::Index offset = 3 + 2 * static_cast<Eigen::Index>(sighting.landmark_id);
    const auto prediction = model.predict(x.head<3>(), x.segment<2>(offset));
    const Eigen::Vector2d weighted = model.Q.llt().solve(model.residual(sighting.z, prediction.z));
    weighted_gradient.head<3>() += prediction.J_z_x.transpose() * weighted;
    weighted_gradient.segment<2>(offset) += prediction.J_z_m.transpose() * weighted;
  }
  return (step - before.covariance() * weighted_gradient).norm() / step.norm();
}

TEST(IteratedEkf, ItsUpdateIsTheOptimumOfPriorAndMeasurementsWhereTheTextbookOneIsNot) {
  const Sightings sightings = sightings_from(kTruthAfterMove);
  double distance[2], pose_error[2];
  for (int iterated : {0, 1}) {
    const Ekf before = filter_before_the_update(iterated ? 10 : 1);
    Ekf after = before;
    after.update(sightings);
    distance[iterated] = distance_from_stationarity(before, after, sightings);
    pose_error[iterated] = (after.pose().mean - kTruthAfterMove).head<2>().norm();
  }
  // Converged to 1e-9 of the step (the iterations' stopping rule), with margin for the roundoff of
  // P0 H^T Q^-1 at condition numbers near 1e4.
  EXPECT_LT(distance[1], 1e-6);
  // The textbook EKF stops at the first linearization: the landmark 5 cm away is seen 0.4 rad off
  // the bearing the prediction gives it, so its H is far from the one at the optimum.
  EXPECT_GT(distance[0], 1e-2);
  std::cout << "distance from the optimum (relative): textbook " << distance[0] << ", iterated " << distance[1]
            << "; position error: textbook " << pose_error[0] << " m, iterated " << pose_error[1] << " m\n";
}

TEST(IteratedEkf, RefusesFewerThanOneLinearization) {
  EXPECT_THROW((Ekf{Se2Odometry{}, sensor(), {Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity()}, {.iterations = 0}}),
               invalid_input_error);
}

using Fast = FastSlam<Se2Odometry, RangeBearing2D>;

/// FastSLAM 2.0's proposal iterated is the same Gauss-Newton over a particle's pose and the landmarks
/// it sees, these marginalized. One particle from an exact start holds what the EKF holds before the
/// update (landmarks independent of each other and of the pose), so its proposal must be the iterated
/// EKF's posterior of the pose, mean and covariance; the textbook proposal, linearized at the running
/// mean, lands elsewhere (the landmark 5 cm away as above).
TEST(IteratedFastSlam, OneParticleFromAnExactStartProposesTheIteratedEkfsPose) {
  const Sightings sightings = sightings_from(kTruthAfterMove);
  Ekf ekf = filter_before_the_update(10);
  ekf.update(sightings);
  const auto exact = ekf.pose();
  Eigen::Vector3d mean[2];
  Eigen::Matrix3d cov[2];
  for (int iterated : {0, 1}) {
    Fast fast = before_the_update(Fast{Se2Odometry{}, sensor(), kExactStart, {.particles = 1, .iterations = iterated ? 10 : 1}});
    fast.update(sightings);
    mean[iterated] = fast.pose().mean;
    cov[iterated] = fast.pose().cov;  // the particle's proposal and its frame's (the start's) covariance
  }
  // Rounding: Kalman and sequential forms of a system of condition number ~1e8, converged to 1e-9. The
  // covariances differ by the start's 1e-10 variance, which the EKF carries into the landmarks it maps
  // and the particle keeps as its frame's: 1e-9 is ten times that.
  EXPECT_LT((mean[1] - exact.mean).norm(), 1e-9);
  EXPECT_LT((cov[1] - exact.cov).norm(), 1e-9);
  EXPECT_GT((mean[0] - exact.mean).head<2>().norm(), 1e-3);
  EXPECT_GT((cov[0] - exact.cov).norm(), 1e-9);
  EXPECT_THROW((Fast{Se2Odometry{}, sensor(), kExactStart, {.iterations = 0}}), invalid_input_error);
  std::cout << "FastSLAM 2.0 proposal's distance from the iterated EKF's pose: textbook " << (mean[0] - exact.mean).norm()
            << " m, iterated " << (mean[1] - exact.mean).norm() << " m; covariance: textbook "
            << (cov[0] - exact.cov).norm() << ", iterated " << (cov[1] - exact.cov).norm() << " (norm "
            << exact.cov.norm() << ")\n";
}

/// The same with the ids withheld: update_unassociated pairs in the first pass (the landmark 5 cm
/// away last, where the three before it have brought the pose within its gate) and iterates what it
/// paired, so the particle proposes the iterated EKF's pose again (folded once: 2.7e-5 m away).
TEST(IteratedFastSlam, WithoutIdsThePairedMeasurementsProposeTheIteratedEkfsPose) {
  const Sightings sightings = sightings_from(kTruthAfterMove);
  Ekf ekf = filter_before_the_update(10);
  ekf.update(sightings);
  const auto exact = ekf.pose();
  const auto measurements_from = [](const Sightings& seen) {
    std::vector<Eigen::Vector2d> z;
    for (std::size_t i : {1, 2, 3, 0}) z.push_back(seen[i].z);
    return z;
  };
  Fast fast{Se2Odometry{}, sensor(), kExactStart, {.particles = 1, .iterations = 10}};
  fast.update_unassociated(measurements_from(sightings_from(Eigen::Vector3d::Zero())));
  fast.predict({Eigen::Vector3d(0.2, 0.0, 0.0), Eigen::Vector3d(0.04 * 0.04, 0.04 * 0.04, 1.75e-4 * 1.75e-4).asDiagonal()}, 1.0);
  const UpdateResult result = fast.update_unassociated(measurements_from(sightings));
  EXPECT_EQ(result.initialized, 0u);
  EXPECT_LT((fast.pose().mean - exact.mean).norm(), 1e-9);  // the bounds of the test above, for its reasons
  EXPECT_LT((fast.pose().cov - exact.cov).norm(), 1e-9);
}

/// EKF = SEIF without sparsification (one Gaussian in two forms), iterated too: both are Gauss-Newton
/// on the same prior and measurements, and SEIF's mean recovery over its active block is exact when
/// every landmark is active. A wrong gradient when a factor is taken out at the moved mean shows here.
TEST(IteratedSeif, WithoutSparsificationIsTheIteratedEkf) {
  const Sightings sightings = sightings_from(kTruthAfterMove);
  Ekf ekf = filter_before_the_update(10);
  Seif seif = before_the_update(Seif{Se2Odometry{}, sensor(), kExactStart, {.iterations = 10}});
  Seif textbook = before_the_update(Seif{Se2Odometry{}, sensor(), kExactStart});
  ekf.update(sightings);
  seif.update(sightings);
  textbook.update(sightings);
  const auto pose = seif.pose();
  // Rounding: the two forms solve systems of condition number ~1e8 (a 1e-10 prior beside centimetres).
  EXPECT_LT((pose.mean - ekf.pose().mean).norm(), 1e-9);
  EXPECT_LT((pose.cov - ekf.pose().cov).norm(), 1e-9 * ekf.pose().cov.norm());
  for (LandmarkId id = 0; id < static_cast<LandmarkId>(kLandmarks.size()); ++id)
    EXPECT_LT((seif.landmark(id).mean - ekf.landmark(id).mean).norm(), 1e-9) << "landmark " << id;
  // and not the textbook SEIF's mean (which is the textbook EKF's): the test can tell them apart
  EXPECT_GT((textbook.pose().mean - pose.mean).head<2>().norm(), 1e-3);
}

/// ESEIF (relocalization) iterated: the step is iterated to its mean before the robot is marginalized,
/// so the held-back measurements relocalize it from a linearization at that mean. The measurements
/// are exact, so the truth is the optimum's robot up to the prior's pull; the relocalized pose must
/// be as likely under its own covariance as a 99.9% chi-square bound allows (2 dof: 13.8), which the
/// textbook relocalization, linearized at the prediction, misses.
TEST(IteratedSeif, RelocalizesFromTheStepsMean) {
  const Sightings sightings = sightings_from(kTruthAfterMove);
  double nees[2], position_error[2];
  for (int iterated : {0, 1}) {
    Seif eseif = before_the_update(Seif{Se2Odometry{}, sensor(), kExactStart,
                                        {.max_active = 2,
                                         .sparsification = SeifSparsification::relocalization,
                                         // any two landmarks may relocalize: the odometry's heading (0.01 deg)
                                         // is 10x the bearings', which the default share would wait for
                                         .relocalization_min_information = 0.0,
                                         .estimate = SeifEstimate::exact_mean,
                                         .iterations = iterated ? 10 : 1}});
    eseif.update(sightings);
    ASSERT_EQ(eseif.relocalizations(), 1u) << "the step must relocalize for this test to mean anything";
    const auto pose = eseif.pose();
    const Eigen::Vector2d error = (pose.mean - kTruthAfterMove).head<2>();
    nees[iterated] = error.dot(pose.cov.topLeftCorner<2, 2>().llt().solve(error));
    position_error[iterated] = error.norm();
  }
  EXPECT_LT(nees[1], 13.8);
  EXPECT_GT(nees[0], 13.8);
  std::cout << "ESEIF position NEES: textbook " << nees[0] << ", iterated " << nees[1] << "; position error: textbook "
            << position_error[0] << " m, iterated " << position_error[1] << " m\n";
}

TEST(IteratedSeif, RefusesFewerThanOneLinearization) {
  EXPECT_THROW((Seif{Se2Odometry{}, sensor(), kExactStart, {.iterations = 0}}), invalid_input_error);
}

}  // namespace
}  // namespace sextant
