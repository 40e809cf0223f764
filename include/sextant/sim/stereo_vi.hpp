#pragma once
/// \file Deterministic, seeded simulator of seed 004's visual-inertial setting: a car drives one
/// closed loop through a street of 3D points, its IMU measures linear and angular velocity, and a
/// rectified stereo camera (KITTI-like intrinsics) measures the points it sees as pixel pairs
/// (uL, vL, uR, vR). The true motion is the ImuVelocitySe3 model itself with its velocity noise
/// (the filters' model is exact, so their consistency can be tested); the pixels carry Gaussian
/// noise of the model's sigma. Frames: the IMU's x forward, y left, z up; the camera's z forward,
/// x right, y down.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <vector>

#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/core/se3.hpp"
#include "sextant/models/stereo_imu_se3.hpp"
#include "sextant/sim/ordered_draws.hpp"

namespace sextant::sim {

/// Parameters of the simulation; units are m, s, rad and px.
struct StereoViOptions {
  std::uint64_t seed = 1;
  int num_steps = 400;              ///< frames; the loop closes at the last one
  double dt = 0.1;                  ///< s (a 10 Hz camera, as KITTI's)
  double speed = 8.0;               ///< m/s along the IMU's x axis
  double weave = 0.05;              ///< rad/s amplitude of a yaw oscillation on top of the loop's turn
  int num_points = 2500;            ///< 3D points along the street
  double street_half_width = 4.0;   ///< m: no point nearer the loop than this (the road)
  double street_depth = 30.0;       ///< m: points up to this far beside the road
  double min_height = -1.5, max_height = 8.0;  ///< m, world z of the points (the IMU starts at 0)
  double max_range = 40.0;          ///< m: farther points are not matched
  int image_width = 1241, image_height = 376;  ///< px (KITTI's)
  int max_features_per_frame = 80;  ///< the nearest points are kept
  StereoCalibration calibration{718.856, 718.856, 607.19, 185.22, 0.537};  ///< KITTI 00-02's rectified pair
  double pixel_sigma = 1.0;         ///< px, on each of uL, vL, uR, vR
  /// px: the dataset's sensor triangulates new landmarks from disparities of at least this (depth
  /// <= 12.9 m with KITTI's pair, depth error <= ~5%); see StereoPixelsSe3::min_disparity.
  double min_disparity = 30.0;
  /// Velocity noise W: 0.1 m/s and 0.01 rad/s per axis.
  se3::Vector6d velocity_sigma = (se3::Vector6d() << 0.1, 0.1, 0.1, 0.01, 0.01, 0.01).finished();
  double prior_sigma_position = 1e-3, prior_sigma_angle = 1e-3;  ///< m, rad
};

struct StereoViDataset {
  ImuVelocitySe3 motion;
  StereoPixelsSe3 sensor;
  Gaussian<Eigen::Matrix4d, 6> prior;
  /// control: the measured velocity over the step (true velocity plus noise drawn from W)
  std::vector<Step<se3::Vector6d, Eigen::Vector4d>> steps;
  std::vector<Eigen::Matrix4d> true_poses;  ///< world_T_imu; true_poses[k]: after step k, [0] the start
  std::map<LandmarkId, Eigen::Vector3d> true_landmarks;
};

namespace detail {

/// The camera of a car: z forward along the IMU's x, x right (-y), y down (-z), 1.5 m ahead and
/// 0.3 m above the IMU.
inline Eigen::Matrix4d car_cam_T_imu() {
  Eigen::Matrix4d imu_T_cam = Eigen::Matrix4d::Identity();
  imu_T_cam.topLeftCorner<3, 3>() << 0, 0, 1,  //
      -1, 0, 0,                                //
      0, -1, 0;
  imu_T_cam.topRightCorner<3, 1>() << 1.5, 0.0, 0.3;
  return se3::inverse(imu_T_cam);
}

/// The true velocity at step k: constant speed, a yaw rate that turns the car once around over
/// the run, with a slow weave on top, and small roll and pitch oscillations (a suspension).
inline se3::Vector6d true_velocity(const StereoViOptions& o, int k) {
  const double t = o.dt * k, duration = o.dt * o.num_steps;
  const double turn = 2.0 * std::numbers::pi / duration;
  se3::Vector6d u;
  u << o.speed, 0.0, 0.0, 0.02 * std::sin(1.3 * t), 0.02 * std::cos(0.9 * t),
      turn + o.weave * std::sin(2.0 * std::numbers::pi * 3.0 * t / duration);
  return u;
}

/// Points beside the loop's noise-free path: a random point of the path, then out to either side
/// by street_half_width .. street_half_width + street_depth, at a random height; ids 0 .. n-1.
inline std::map<LandmarkId, Eigen::Vector3d> street_points(const StereoViOptions& o, std::mt19937_64& rng) {
  std::vector<Eigen::Matrix4d> path{Eigen::Matrix4d::Identity()};
  for (int k = 0; k < o.num_steps; ++k) path.push_back(path.back() * se3::exp(o.dt * true_velocity(o, k)));
  std::uniform_int_distribution<std::size_t> along(0, path.size() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::map<LandmarkId, Eigen::Vector3d> points;
  for (int i = 0; i < o.num_points; ++i) {
    const Eigen::Matrix4d& T = path[along(rng)];
    const double side = unit(rng) < 0.5 ? -1.0 : 1.0;
    const double offset = side * (o.street_half_width + o.street_depth * unit(rng));
    const double height = o.min_height + (o.max_height - o.min_height) * unit(rng);
    const Eigen::Vector3d lateral = T.block<3, 1>(0, 1);  // the car's left
    Eigen::Vector3d p = T.topRightCorner<3, 1>() + offset * lateral;
    p.z() = height;
    points.emplace(static_cast<LandmarkId>(i), p);
  }
  return points;
}

/// The pixel pairs of the points the left and right cameras both see, nearest first, at most
/// max_features_per_frame; noise-free.
inline std::vector<Observation<Eigen::Vector4d>> visible_pixels(const StereoViOptions& o, const StereoPixelsSe3& sensor,
                                                                const Eigen::Matrix4d& world_T_imu,
                                                                const std::map<LandmarkId, Eigen::Vector3d>& points) {
  struct Seen {
    double depth;
    Observation<Eigen::Vector4d> observation;
  };
  std::vector<Seen> seen;
  const Eigen::Matrix4d cam_T_world = sensor.cam_T_imu * se3::inverse(world_T_imu);
  for (const auto& [id, p] : points) {
    const Eigen::Vector3d q = (cam_T_world * p.homogeneous()).head<3>();
    if (q.z() < 1.0 || q.norm() > o.max_range || !sensor.sees(q)) continue;
    const Eigen::Vector4d z = sensor.predict(world_T_imu, p).z;
    const bool inside = z(0) >= 0 && z(0) < o.image_width && z(2) >= 0 && z(2) < o.image_width && z(1) >= 0 &&
                        z(1) < o.image_height;
    if (inside) seen.push_back({q.z(), {id, z}});
  }
  std::sort(seen.begin(), seen.end(), [](const Seen& a, const Seen& b) { return a.depth < b.depth; });
  if (seen.size() > static_cast<std::size_t>(o.max_features_per_frame))
    seen.resize(static_cast<std::size_t>(o.max_features_per_frame));
  std::vector<Observation<Eigen::Vector4d>> out;
  for (const auto& s : seen) out.push_back(s.observation);
  return out;
}

}  // namespace detail

inline StereoViDataset simulate_stereo_vi(const StereoViOptions& o = {}) {
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  StereoViDataset data;
  data.motion.W = o.velocity_sigma.cwiseAbs2().asDiagonal();
  data.sensor.calibration = o.calibration;
  data.sensor.cam_T_imu = detail::car_cam_T_imu();
  data.sensor.pixel_sigma = o.pixel_sigma;
  data.sensor.min_disparity = o.min_disparity;
  data.true_landmarks = detail::street_points(o, rng);

  Eigen::Matrix4d x = Eigen::Matrix4d::Identity();
  data.true_poses.push_back(x);
  se3::Vector6d prior_sigma;
  prior_sigma << Eigen::Vector3d::Constant(o.prior_sigma_position), Eigen::Vector3d::Constant(o.prior_sigma_angle);
  data.prior.cov = prior_sigma.cwiseAbs2().asDiagonal();
  data.prior.mean = Se3Space::plus(x, prior_sigma.cwiseProduct(ordered_draws<6>(normal, rng)));

  for (int k = 0; k < o.num_steps; ++k) {
    const se3::Vector6d u = detail::true_velocity(o, k);
    const se3::Vector6d w = o.velocity_sigma.cwiseProduct(ordered_draws<6>(normal, rng));
    x = se3::normalized(x * se3::exp(o.dt * u));  // the truth: the measured velocity is u + w
    data.true_poses.push_back(x);
    Step<se3::Vector6d, Eigen::Vector4d> step{u + w, o.dt, {}};
    for (auto observation : detail::visible_pixels(o, data.sensor, x, data.true_landmarks)) {
      observation.z += o.pixel_sigma * ordered_draws<4>(normal, rng);
      step.observations.push_back(observation);
    }
    data.steps.push_back(std::move(step));
  }
  return data;
}

}  // namespace sextant::sim
