#include "sextant/eval/alignment.hpp"
#include "sextant/sim/ordered_draws.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace sextant::eval {
namespace {

TEST(Alignment, RecoversARigidMotionExactlyIn2dAnd3d) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> truth, moved;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(4.0, -2.0, 0.5);
  for (int i = 0; i < 20; ++i) {
    truth.push_back(sim::ordered_draws<3>(unit, rng));
    moved.push_back(R.transpose() * (truth.back() - t));  // estimate = T^-1(truth)
  }
  const auto T = align_rigidly<3>(moved, truth);
  EXPECT_LT((T.R - R).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((T.t - t).cwiseAbs().maxCoeff(), 1e-12);
  for (double e : aligned_errors<3>(moved, truth)) EXPECT_LT(e, 1e-12);

  std::vector<Eigen::Vector2d> truth2{{0, 0}, {1, 0}, {0, 2}}, moved2;
  const Eigen::Matrix2d R2 = Eigen::Rotation2Dd(-2.0).toRotationMatrix();
  for (const auto& p : truth2) moved2.push_back(R2 * p + Eigen::Vector2d(1, 1));
  for (double e : aligned_errors<2>(moved2, truth2)) EXPECT_LT(e, 1e-12);
}

TEST(Alignment, NeverReflects) {
  // A mirrored point set: the best proper rotation leaves an error; a reflection would leave none.
  std::vector<Eigen::Vector2d> truth{{1, 0}, {0, 1}, {2, 3}}, mirrored;
  for (const auto& p : truth) mirrored.emplace_back(-p.x(), p.y());
  const auto T = align_rigidly<2>(mirrored, truth);
  EXPECT_NEAR(T.R.determinant(), 1.0, 1e-12);
  double worst = 0.0;
  for (double e : aligned_errors<2>(mirrored, truth)) worst = std::max(worst, e);
  EXPECT_GT(worst, 0.1);
}

TEST(Alignment, RejectsSetsOfDifferentSizes) {
  EXPECT_THROW(align_rigidly<2>({Eigen::Vector2d::Zero()}, {}), invalid_input_error);
}

}  // namespace
}  // namespace sextant::eval
