// Bad input gives a sextant::error naming the problem, and the filter's state stays exactly as it was.
#include <gtest/gtest.h>

#include <limits>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/eval/runner.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "support/batch_least_squares.hpp"

namespace sextant {
namespace {

using Ekf = EkfSlam<BeaconShip2D, BeaconOffset2D>;
using Obs = Observation<Eigen::Vector2d>;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Snapshot {
  Eigen::Vector2d pose;
  Eigen::MatrixXd cov;
  std::vector<LandmarkEstimate<2>> map;
};
Snapshot snapshot(const Ekf& ekf) { return {ekf.pose().mean, ekf.covariance(), ekf.map()}; }
void expect_unchanged(const Snapshot& before, const Ekf& ekf) {
  EXPECT_EQ(before.pose, ekf.pose().mean);
  EXPECT_EQ(before.cov, Eigen::MatrixXd(ekf.covariance()));
  const auto map = ekf.map();
  ASSERT_EQ(before.map.size(), map.size());
  for (std::size_t i = 0; i < map.size(); ++i) {
    EXPECT_EQ(before.map[i].id, map[i].id);
    EXPECT_EQ(before.map[i].mean, map[i].mean);
    EXPECT_EQ(before.map[i].cov, map[i].cov);
  }
}

class EkfBadInput : public ::testing::TestWithParam<bool> {  // batch or sequential update
 protected:
  EkfBadInput()
      : ekf_{BeaconShip2D{}, BeaconOffset2D{}, {Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity()},
             {.batch_update = GetParam()}} {
    eval::run(ekf_, test::random_linear_steps(12, 5, 3));
  }
  template <class Call>
  void expect_error_and_no_change(Call call, const std::string& fragment) {
    const Snapshot before = snapshot(ekf_);
    try {
      call();
      ADD_FAILURE() << "expected a sextant::error mentioning '" << fragment << "'";
    } catch (const error& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
    expect_unchanged(before, ekf_);
  }
  LandmarkId known(std::size_t i) const { return ekf_.landmark_ids().at(i); }
  Ekf ekf_;
};

TEST_P(EkfBadInput, NaNOrInfControl) {
  expect_error_and_no_change([&] { ekf_.predict(Eigen::Vector2d(kNaN, 0.0), 1.0); }, "control");
  expect_error_and_no_change([&] { ekf_.predict(Eigen::Vector2d(1.0, kInf), 1.0); }, "control");
}

TEST_P(EkfBadInput, NonPositiveOrNonFiniteTimeStep) {
  for (double dt : {0.0, -1.0, kNaN, kInf})
    expect_error_and_no_change([&] { ekf_.predict(Eigen::Vector2d(1.0, 0.0), dt); }, "dt");
}

TEST_P(EkfBadInput, NaNMeasurementAfterValidOnesInTheSameUpdate) {
  const std::vector<Obs> observations{{known(0), {1.0, 1.0}}, {known(1), {2.0, 1.0}}, {999, {1.0, 1.0}},
                                      {known(2), {kNaN, 0.0}}};
  expect_error_and_no_change([&] { ekf_.update(observations); }, "measurement of landmark " + std::to_string(known(2)));
}

TEST_P(EkfBadInput, LandmarkRepeatedWithinOneUpdate) {
  const std::vector<Obs> repeated_known{{known(0), {1.0, 1.0}}, {known(1), {2.0, 1.0}}, {known(0), {1.1, 1.0}}};
  expect_error_and_no_change([&] { ekf_.update(repeated_known); }, "twice");
  const std::vector<Obs> repeated_new{{500, {1.0, 1.0}}, {500, {1.0, 1.1}}};
  expect_error_and_no_change([&] { ekf_.update(repeated_new); }, "twice");
}

TEST_P(EkfBadInput, RemoveUnknownLandmark) {
  expect_error_and_no_change([&] { ekf_.remove_landmark(12345); }, "unknown landmark id 12345");
  EXPECT_THROW(ekf_.remove_landmark(12345), unknown_landmark_error);
}

/// A sensor whose noise is indefinite for one landmark: the innovation matrix is not PD.
struct BrokenNoiseSensor : BeaconOffset2D {
  MeasurementPrediction<2, 2, 2> predict(const Eigen::Vector2d& x, const Landmark& m) const {
    auto out = BeaconOffset2D::predict(x, m);
    if (m.x() > 1e5) out.Q = -1e9 * Eigen::Matrix2d::Identity();
    return out;
  }
};

TEST_P(EkfBadInput, InnovationNotPositiveDefinite) {
  EkfSlam<BeaconShip2D, BrokenNoiseSensor> ekf{BeaconShip2D{}, BrokenNoiseSensor{},
                                               {Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity()},
                                               {.batch_update = GetParam()}};
  ekf.update(std::vector<Obs>{{1, {1.0, 0.0}}, {2, {2e5, 0.0}}});
  const Eigen::MatrixXd before = ekf.covariance();
  const Eigen::Vector2d pose_before = ekf.pose().mean;
  try {
    ekf.update(std::vector<Obs>{{1, {1.1, 0.0}}, {2, {2e5, 0.0}}, {3, {0.0, 1.0}}});
    ADD_FAILURE() << "expected numerical_error";
  } catch (const numerical_error& e) {
    EXPECT_NE(std::string(e.what()).find("not positive definite"), std::string::npos) << e.what();
  }
  EXPECT_EQ(before, Eigen::MatrixXd(ekf.covariance()));
  EXPECT_EQ(pose_before, ekf.pose().mean);
  EXPECT_FALSE(ekf.has_landmark(3));
}

TEST(EkfBadPrior, NonFiniteOrIndefinitePriorIsRejected) {
  EXPECT_THROW((Ekf{BeaconShip2D{}, BeaconOffset2D{}, {Eigen::Vector2d(kNaN, 0.0), Eigen::Matrix2d::Identity()}}),
               invalid_input_error);
  EXPECT_THROW((Ekf{BeaconShip2D{}, BeaconOffset2D{}, {Eigen::Vector2d::Zero(), -Eigen::Matrix2d::Identity()}}),
               numerical_error);
}

INSTANTIATE_TEST_SUITE_P(BatchAndSequential, EkfBadInput, ::testing::Bool());

}  // namespace
}  // namespace sextant
