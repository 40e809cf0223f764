#pragma once
// A linear-Gaussian world with a conditionally linear tail (core/conditionally_linear.hpp): the
// Kalman filter (the library's EKF) is its exact posterior, against which FastSLAM's Rao-Blackwellized
// tail and SEIF's relocalization of an unseen tail are checked.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <random>
#include <vector>

#include "sextant/core/model_results.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/core/state_space.hpp"

namespace sextant::test {

/// A point moving at a nearly constant velocity in the plane, state (p, v) with white-acceleration
/// noise of density q, seeing the offsets m - p of landmarks: linear and Gaussian, so the Kalman
/// filter (our EKF) is exact, and v is a conditionally linear tail.
struct ConstantVelocityPoint {
  using State = Eigen::Vector4d;
  using Control = Eigen::Matrix<double, 0, 1>;
  using Space = EuclideanSpace<4>;
  static constexpr int kDim = 4;
  static constexpr int kConditionallyLinearDims = 2;
  double q = 0.02;
  MotionPrediction<State, 4> predict(const State& x, const Control& /*u*/, double dt) const {
    MotionPrediction<State, 4> out;
    out.J_x_x.setIdentity();
    out.J_x_x.topRightCorner<2, 2>() = dt * Eigen::Matrix2d::Identity();
    out.x = out.J_x_x * x;
    out.R.setZero();
    out.R.topLeftCorner<2, 2>() = q * dt * dt * dt / 3.0 * Eigen::Matrix2d::Identity();
    out.R.topRightCorner<2, 2>() = out.R.bottomLeftCorner<2, 2>() = q * dt * dt / 2.0 * Eigen::Matrix2d::Identity();
    out.R.bottomRightCorner<2, 2>() = q * dt * Eigen::Matrix2d::Identity();
    return out;
  }
};
struct PointOffset {
  using Landmark = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;
  double sigma = 0.05;
  MeasurementPrediction<2, 4, 2> predict(const Eigen::Vector4d& x, const Landmark& m) const {
    MeasurementPrediction<2, 4, 2> out;
    out.z = m - x.head<2>();
    out.J_z_x << -Eigen::Matrix2d::Identity(), Eigen::Matrix2d::Zero();
    out.J_z_m.setIdentity();
    out.Q = sigma * sigma * Eigen::Matrix2d::Identity();
    return out;
  }
  Measurement residual(const Measurement& z, const Measurement& z_hat) const { return z - z_hat; }
  LandmarkInit<2, 4, 2> initialize(const Eigen::Vector4d& x, const Measurement& z) const {
    LandmarkInit<2, 4, 2> out;
    out.m = x.head<2>() + z;
    out.J_m_x << Eigen::Matrix2d::Identity(), Eigen::Matrix2d::Zero();
    out.J_m_z.setIdentity();
    out.Q = sigma * sigma * Eigen::Matrix2d::Identity();
    return out;
  }
};

/// The true state dt after x: the model's mean plus a draw of its noise (four draws of `unit`).
inline Eigen::Vector4d moved(const ConstantVelocityPoint& motion, const Eigen::Vector4d& x, double dt, std::mt19937_64& rng,
                             std::normal_distribution<double>& unit) {
  const auto p = motion.predict(x, {}, dt);
  const Eigen::LLT<Eigen::Matrix4d> noise(p.R);
  return p.x + noise.matrixL() * Eigen::Vector4d(unit(rng), unit(rng), unit(rng), unit(rng));
}

/// Every landmark seen from the true state, id = its index, with the sensor's noise.
inline std::vector<Observation<Eigen::Vector2d>> sightings(const std::vector<Eigen::Vector2d>& landmarks,
                                                           const Eigen::Vector4d& truth, const PointOffset& sensor,
                                                           std::mt19937_64& rng, std::normal_distribution<double>& unit) {
  std::vector<Observation<Eigen::Vector2d>> seen;
  for (std::size_t j = 0; j < landmarks.size(); ++j)
    seen.push_back({j, landmarks[j] - truth.head<2>() + sensor.sigma * Eigen::Vector2d(unit(rng), unit(rng))});
  return seen;
}

}  // namespace sextant::test
