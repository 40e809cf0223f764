// EkfSlam::add_landmark: a landmark known before it is seen (a surveyed map) enters with its own
// mean and covariance, uncorrelated with the robot and the map, and the next update is the Kalman
// update of that joint Gaussian; bad input leaves the filter as it was.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <vector>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/se2_odometry.hpp"

namespace sextant {
namespace {

using Ekf = EkfSlam<Se2Odometry, RangeBearing2D>;

RangeBearing2D sensor() {
  RangeBearing2D out;
  out.Q = Eigen::Vector2d(0.05 * 0.05, 0.01 * 0.01).asDiagonal();
  return out;
}

const Ekf::PoseEstimate kStart{Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0.04, 0.09, 0.01).asDiagonal()};
const LandmarkEstimate<2> kSurveyed{7, Eigen::Vector2d(2.0, 1.0), (Eigen::Matrix2d() << 0.02, 0.005, 0.005, 0.03).finished()};

/// A filter after one step of odometry with a map of one landmark seen before (id 3), so that the
/// robot is correlated with the map when the known landmark comes in.
Ekf filter_with_a_map() {
  Ekf ekf(Se2Odometry{}, sensor(), kStart);
  ekf.update(std::vector<Observation<Eigen::Vector2d>>{{3, Eigen::Vector2d(1.5, -0.4)}});
  ekf.predict({Eigen::Vector3d(0.5, 0.1, 0.05), Eigen::Vector3d(0.01, 0.01, 0.002).asDiagonal()}, 1.0);
  return ekf;
}

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

TEST(KnownLandmarks, BadOnesAreRefusedAndTheFilterStaysAsItWas) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Ekf ekf = filter_with_a_map();
  const Eigen::MatrixXd cov = ekf.covariance();
  const Eigen::Vector3d pose = ekf.pose().mean;
  auto expect_unchanged = [&] {
    EXPECT_EQ(ekf.covariance(), cov);
    EXPECT_EQ(ekf.pose().mean, pose);
    EXPECT_EQ(ekf.num_landmarks(), 1u);
  };
  LandmarkEstimate<2> bad = kSurveyed;
  bad.id = 3;  // seen already
  EXPECT_THROW(ekf.add_landmark(bad), duplicate_landmark_error);
  expect_unchanged();
  bad = kSurveyed;
  bad.mean.x() = nan;
  EXPECT_THROW(ekf.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  bad = kSurveyed;
  bad.cov(1, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(ekf.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  bad = kSurveyed;
  bad.cov(0, 1) = 0.01;  // not symmetric
  EXPECT_THROW(ekf.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  bad = kSurveyed;
  bad.cov << 0.02, 0.03, 0.03, 0.02;  // symmetric, eigenvalue -0.01
  EXPECT_THROW(ekf.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  bad.cov.setZero();  // a known landmark still has some uncertainty
  EXPECT_THROW(ekf.add_landmark(bad), invalid_input_error);
  expect_unchanged();
  ekf.add_landmark(kSurveyed);
  EXPECT_THROW(ekf.add_landmark(kSurveyed), duplicate_landmark_error);
  EXPECT_EQ(ekf.num_landmarks(), 2u);
}

}  // namespace
}  // namespace sextant
