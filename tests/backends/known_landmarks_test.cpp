// EkfSlam::add_landmark and SeifSlam::add_landmark: a landmark known before it is seen (a surveyed
// map) enters with its own mean and covariance, uncorrelated with the robot and the map, and the next
// update is the Kalman update of that joint Gaussian (SEIF without sparsification: the same); bad
// input leaves the filter as it was.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/se2_odometry.hpp"

namespace sextant {
namespace {

using Ekf = EkfSlam<Se2Odometry, RangeBearing2D>;
using Seif = SeifSlam<Se2Odometry, RangeBearing2D>;

RangeBearing2D sensor() {
  RangeBearing2D out;
  out.Q = Eigen::Vector2d(0.05 * 0.05, 0.01 * 0.01).asDiagonal();
  return out;
}

const Ekf::PoseEstimate kStart{Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0.04, 0.09, 0.01).asDiagonal()};
const LandmarkEstimate<2> kSurveyed{7, Eigen::Vector2d(2.0, 1.0), (Eigen::Matrix2d() << 0.02, 0.005, 0.005, 0.03).finished()};

/// A filter after one step of odometry with a map of one landmark seen before (id 3), so that the
/// robot is correlated with the map when the known landmark comes in.
template <class Filter>
Filter with_a_map(Filter filter) {
  filter.update(std::vector<Observation<Eigen::Vector2d>>{{3, Eigen::Vector2d(1.5, -0.4)}});
  filter.predict({Eigen::Vector3d(0.5, 0.1, 0.05), Eigen::Vector3d(0.01, 0.01, 0.002).asDiagonal()}, 1.0);
  return filter;
}
Ekf filter_with_a_map() { return with_a_map(Ekf(Se2Odometry{}, sensor(), kStart)); }

TEST(KnownLandmarks, EnterWithTheirCovarianceAndNoCorrelation) {
  Ekf ekf = filter_with_a_map();
  const Eigen::MatrixXd before = ekf.covariance();
  ekf.add_landmark(kSurveyed);
  ASSERT_TRUE(ekf.has_landmark(kSurveyed.id));
  const Eigen::MatrixXd after = ekf.covariance();
  ASSERT_EQ(after.rows(), before.rows() + 2);
  EXPECT_EQ(after.topLeftCorner(before.rows(), before.cols()), before);
  EXPECT_EQ(after.bottomLeftCorner(2, before.cols()), Eigen::MatrixXd::Zero(2, before.cols()));
  EXPECT_EQ(Eigen::Matrix2d(after.bottomRightCorner(2, 2)), kSurveyed.cov);
  EXPECT_EQ(ekf.landmark(kSurveyed.id).mean, kSurveyed.mean);
}

/// The update that sees the known landmark is the Kalman update of the joint Gaussian (robot, seen
/// landmark, known landmark) with the known landmark's block as given: written out here with the
/// sensor's Jacobians at the prior mean, the Joseph form of the covariance.
TEST(KnownLandmarks, TheNextUpdateIsTheKalmanUpdateOfTheJointGaussian) {
  Ekf ekf = filter_with_a_map();
  ekf.add_landmark(kSurveyed);
  const Eigen::VectorXd mu = [&] {
    Eigen::VectorXd out(7);
    out << ekf.pose().mean, ekf.landmark(3).mean, kSurveyed.mean;
    return out;
  }();
  const Eigen::MatrixXd P = ekf.covariance();  // slots: robot, landmark 3, landmark 7
  const Eigen::Vector2d z(2.1, 0.35);
  const auto h = sensor().predict(mu.head<3>(), mu.tail<2>());
  Eigen::Matrix<double, 2, 7> H = Eigen::Matrix<double, 2, 7>::Zero();
  H.leftCols<3>() = h.J_z_x;
  H.rightCols<2>() = h.J_z_m;
  const Eigen::Matrix2d S = H * P * H.transpose() + h.Q;
  const Eigen::Matrix<double, 7, 2> K = P * H.transpose() * S.inverse();
  const Eigen::VectorXd expected_mean = mu + K * sensor().residual(z, h.z);
  const Eigen::Matrix<double, 7, 7> I_KH = Eigen::Matrix<double, 7, 7>::Identity() - K * H;
  const Eigen::MatrixXd expected_cov = I_KH * P * I_KH.transpose() + K * h.Q * K.transpose();

  ekf.update(std::vector<Observation<Eigen::Vector2d>>{{kSurveyed.id, z}});
  EXPECT_LT((ekf.pose().mean - expected_mean.head<3>()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ekf.landmark(3).mean - expected_mean.segment<2>(3)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ekf.landmark(kSurveyed.id).mean - expected_mean.tail<2>()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ekf.covariance() - expected_cov).cwiseAbs().maxCoeff(), 1e-12);
  // The robot learnt from a landmark it had never seen: its position variance fell.
  EXPECT_LT(ekf.pose().cov.trace(), P.topLeftCorner(3, 3).trace());
}

/// Each bad landmark is refused with the error that names it and leaves `filter` as it was
/// (`expect_unchanged`, over the filter's one seen landmark); then the good one goes in, once.
template <class Filter, class ExpectUnchanged>
void expect_bad_ones_refused(Filter& filter, ExpectUnchanged expect_unchanged) {
  LandmarkEstimate<2> bad = kSurveyed;
  bad.id = 3;  // seen already
  EXPECT_THROW(filter.add_landmark(bad), duplicate_landmark_error);
  expect_unchanged();
  bad = kSurveyed;
  bad.mean.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(filter.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  bad = kSurveyed;
  bad.cov(1, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(filter.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  bad = kSurveyed;
  bad.cov(0, 1) = 0.01;  // not symmetric
  EXPECT_THROW(filter.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  bad = kSurveyed;
  bad.cov << 0.02, 0.03, 0.03, 0.02;  // symmetric, eigenvalue -0.01
  EXPECT_THROW(filter.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  bad.cov.setZero();  // a known landmark still has some uncertainty
  EXPECT_THROW(filter.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  filter.add_landmark(kSurveyed);
  EXPECT_THROW(filter.add_landmark(kSurveyed), duplicate_landmark_error);
  EXPECT_EQ(filter.num_landmarks(), 2u);
}

TEST(KnownLandmarks, BadOnesAreRefusedAndTheFilterStaysAsItWas) {
  Ekf ekf = filter_with_a_map();
  const Eigen::MatrixXd cov = ekf.covariance();
  const Eigen::Vector3d pose = ekf.pose().mean;
  expect_bad_ones_refused(ekf, [&] {
    EXPECT_EQ(ekf.covariance(), cov);
    EXPECT_EQ(ekf.pose().mean, pose);
    EXPECT_EQ(ekf.num_landmarks(), 1u);
  });
}

/// Largest difference between the two filters' pose and landmark means (absolute) and covariances
/// (relative to the EKF's largest entry).
double largest_difference(const Ekf& ekf, const Seif& seif) {
  const auto relative = [](const auto& a, const auto& b) { return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff(); };
  double out = std::max((seif.pose().mean - ekf.pose().mean).cwiseAbs().maxCoeff(), relative(seif.pose().cov, ekf.pose().cov));
  for (const auto& landmark : ekf.map()) {
    const auto other = seif.landmark(landmark.id);
    out = std::max({out, (other.mean - landmark.mean).cwiseAbs().maxCoeff(), relative(other.cov, landmark.cov)});
  }
  return out;
}

/// SEIF without sparsification is the EKF in information form (thesis §5), so a surveyed landmark,
/// an information block cov^-1 with no link, must leave it equal to the EKF given the same one, at
/// once and through the updates that see it. Bound: rounding of the information form's solves over a
/// few steps (the whole ship run stays within 1e-6, seif_slam_test).
TEST(KnownLandmarks, SeifWithoutSparsificationTakesThemAsTheEkfDoes) {
  Ekf ekf = filter_with_a_map();
  Seif seif = with_a_map(Seif(Se2Odometry{}, sensor(), kStart, {.max_active = 0, .exact_recovery_period = 1}));
  ASSERT_LT(largest_difference(ekf, seif), 1e-9);
  ekf.add_landmark(kSurveyed);
  seif.add_landmark(kSurveyed);
  ASSERT_TRUE(seif.has_landmark(kSurveyed.id));
  EXPECT_LT(largest_difference(ekf, seif), 1e-9);
  const std::vector<Observation<Eigen::Vector2d>> sightings{{kSurveyed.id, Eigen::Vector2d(2.1, 0.35)},
                                                            {3, Eigen::Vector2d(1.2, -0.5)}};
  for (int k = 0; k < 3; ++k) {
    ekf.update(sightings);
    seif.update(sightings);
    EXPECT_LT(largest_difference(ekf, seif), 1e-9) << "update " << k;
    ekf.predict({Eigen::Vector3d(0.05, 0.0, 0.01), Eigen::Vector3d(0.001, 0.001, 0.0002).asDiagonal()}, 1.0);
    seif.predict({Eigen::Vector3d(0.05, 0.0, 0.01), Eigen::Vector3d(0.001, 0.001, 0.0002).asDiagonal()}, 1.0);
  }
  EXPECT_LT(seif.landmark(kSurveyed.id).cov.trace(), kSurveyed.cov.trace());  // the sightings refined it
}

TEST(KnownLandmarks, SeifRefusesBadOnesAndStaysAsItWas) {
  Seif seif = with_a_map(Seif(Se2Odometry{}, sensor(), kStart));
  const auto pose = seif.pose();
  const auto map = seif.map();
  expect_bad_ones_refused(seif, [&] {
    EXPECT_EQ(seif.pose().mean, pose.mean);
    EXPECT_EQ(seif.pose().cov, pose.cov);
    ASSERT_EQ(seif.map().size(), map.size());
    EXPECT_EQ(seif.map().front().mean, map.front().mean);
  });
}

}  // namespace
}  // namespace sextant
