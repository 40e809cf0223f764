#pragma once
/// \file Deterministic, seeded simulator of the thesis's visual SLAM experiment (seed 000, §4.2.2,
/// §5.2): a handheld stereo camera circles a decorative globe, looking at it, and sees feature
/// points on its surface. The true motion is the EulerCamera12D model itself with its process noise
/// (so the filters' model is exact and their consistency can be tested); the measurements are 3D
/// points in the camera frame with the anisotropic noise of a stereo pair (StereoPointNoise).

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
#include "sextant/models/euler_camera_12d.hpp"

namespace sextant::sim {

/// Parameters of the globe simulation; units are m, s and rad. The world frame has y pointing
/// down (as the camera's) and its origin at the globe's centre.
struct GlobeCameraOptions {
  std::uint64_t seed = 1;
  int num_steps = 500;           ///< thesis: 500 time instances
  double dt = 1.0 / 15.0;        ///< s (15 frames per second)
  int loop_step = 420;           ///< the circle closes near this step
  double globe_radius = 0.15;    ///< m
  int num_points = 3000;         ///< feature points on the globe's surface
  double orbit_radius = 0.45;    ///< m, horizontal distance of the camera from the globe's axis
  double orbit_height = -0.10;   ///< m, camera height (y down: negative is above the equator)
  int image_width = 640, image_height = 480;  ///< px; principal point at the centre
  int max_features_per_frame = 120;  ///< the detector keeps the strongest responses
  /// Log-normal frame-to-frame noise on each response (standard deviation of its logarithm): a real
  /// detector's responses change with blur, lighting and viewpoint, so which features pass the cut
  /// changes between frames and new ones keep entering the map (the thesis's real images, Figure 25).
  /// 0 = the same strongest points every frame. Drawn from its own stream: it leaves the rest alone.
  double response_jitter = 0.0;
  double border_px = 8.0;        ///< features nearer the image border are not detected
  StereoPointNoise stereo{};     ///< focal length, baseline, pixel noise
  EulerCamera12D motion{};       ///< the motion model and its process noise (also the truth's)
  double prior_sigma_position = 1e-3, prior_sigma_angle = 1e-3;   ///< m, rad
  /// m/s, rad/s: the start's motion known to ~2% of the orbit's speed and rate, as a front-end
  /// that initializes from its first frames would know it
  double prior_sigma_velocity = 2e-3, prior_sigma_rate = 5e-3;
};

struct GlobeCameraDataset {
  using Control = EulerCamera12D::Control;
  EulerCamera12D motion;
  PointInCamera3D sensor;
  Gaussian<Vector12d, 12> prior;
  std::vector<Step<Control, Eigen::Vector3d>> steps;
  std::vector<Vector12d> true_poses;  ///< true_poses[k]: after step k; [0] is the start
  std::map<LandmarkId, Eigen::Vector3d> true_landmarks;
  int image_width = 0, image_height = 0;
  double focal_px = 0.0;
};

namespace detail {

/// Points spread evenly over the sphere (a Fibonacci lattice), each moved at random within its
/// cell so that no pattern repeats; ids 0 .. n-1.
inline std::map<LandmarkId, Eigen::Vector3d> globe_points(const GlobeCameraOptions& o, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> jitter(-0.5, 0.5);
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::map<LandmarkId, Eigen::Vector3d> points;
  for (int i = 0; i < o.num_points; ++i) {
    const double y = std::clamp(1.0 - 2.0 * (i + 0.5 + jitter(rng)) / o.num_points, -1.0, 1.0);
    const double ring = std::sqrt(1.0 - y * y), azimuth = golden * (i + 0.5 * jitter(rng));
    points.emplace(static_cast<LandmarkId>(i),
                   o.globe_radius * Eigen::Vector3d(ring * std::cos(azimuth), y, ring * std::sin(azimuth)));
  }
  return points;
}

/// The start of the orbit: the camera at (0, height, -radius) looking at the globe's centre; it
/// circles clockwise seen from above (about -y) with constant body velocity and rate, closing the
/// circle after loop_step steps.
inline Vector12d orbit_start(const GlobeCameraOptions& o) {
  const Eigen::Vector3d p0(0.0, o.orbit_height, -o.orbit_radius);
  const double phi = -std::atan2(-o.orbit_height, o.orbit_radius);  // tilt the optical axis to the centre
  const Eigen::Matrix3d R0 = euler_yxz::rotation_x(phi);
  const double theta_rate = 2.0 * std::numbers::pi / (o.loop_step * o.dt);  // about world +y (down)
  Vector12d x;
  x << p0, phi, 0.0, 0.0, R0.transpose() * (theta_rate * so3::hat(Eigen::Vector3d::UnitY()) * p0),
      theta_rate * (R0.transpose() * Eigen::Vector3d::UnitY());
  return x;
}

/// Detector response of each point: a fixed strength per point times the cosine of the angle
/// between the surface normal and the ray to the camera (features at the limb are weak).
struct Detection {
  LandmarkId id;
  double score;
  Eigen::Vector3d in_camera;
};

inline std::vector<Detection> visible_points(const GlobeCameraOptions& o, const Vector12d& x,
                                             const std::map<LandmarkId, Eigen::Vector3d>& points,
                                             const std::vector<double>& strength) {
  const Eigen::Vector3d p = x.head<3>();
  const Eigen::Matrix3d R = euler_yxz::rotation(x.segment<3>(3));
  const double f = o.stereo.focal_px, half_w = 0.5 * o.image_width - o.border_px,
               half_h = 0.5 * o.image_height - o.border_px;
  std::vector<Detection> out;
  for (const auto& [id, m] : points) {
    const Eigen::Vector3d to_camera = p - m;
    const double facing = m.normalized().dot(to_camera.normalized());
    if (facing <= 0.0) continue;  // the far hemisphere
    const Eigen::Vector3d q = R.transpose() * (m - p);
    if (q.z() <= o.stereo.min_depth) continue;  // behind or too near
    const double u = f * q.x() / q.z(), v = f * q.y() / q.z(), disparity = f * o.stereo.baseline / q.z();
    if (std::abs(u) > half_w || std::abs(v) > half_h || std::abs(u - disparity) > half_w) continue;
    out.push_back({id, strength[id] * facing, q});
  }
  return out;
}

}  // namespace detail

/// Simulates one run. The same options (including seed) always give the same data.
inline GlobeCameraDataset simulate_globe_camera(const GlobeCameraOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  auto gaussian = [&](const auto& cov) {
    using Vector = Eigen::Matrix<double, std::decay_t<decltype(cov)>::RowsAtCompileTime, 1>;
    Vector n;
    for (auto& e : n) e = unit(rng);
    return Vector(Eigen::LLT<std::decay_t<decltype(cov)>>(cov).matrixL() * n);
  };

  GlobeCameraDataset data;
  data.motion = o.motion;
  data.sensor.noise = o.stereo;
  data.image_width = o.image_width;
  data.image_height = o.image_height;
  data.focal_px = o.stereo.focal_px;
  data.true_landmarks = detail::globe_points(o, rng);
  std::vector<double> strength(data.true_landmarks.size());
  for (auto& s : strength) s = uniform(rng);

  std::mt19937_64 jitter_rng(o.seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> jitter(0.0, o.response_jitter);
  Vector12d x = detail::orbit_start(o);
  data.true_poses.push_back(x);
  Vector12d prior_variance;
  prior_variance << Eigen::Vector3d::Constant(o.prior_sigma_position * o.prior_sigma_position),
      Eigen::Vector3d::Constant(o.prior_sigma_angle * o.prior_sigma_angle),
      Eigen::Vector3d::Constant(o.prior_sigma_velocity * o.prior_sigma_velocity),
      Eigen::Vector3d::Constant(o.prior_sigma_rate * o.prior_sigma_rate);
  data.prior.cov = prior_variance.asDiagonal();
  data.prior.mean = EulerCamera12Space::plus(x, gaussian(data.prior.cov));

  for (int k = 0; k < o.num_steps; ++k) {
    const auto prediction = o.motion.predict(x, {}, o.dt);
    x = EulerCamera12Space::plus(prediction.x, gaussian(prediction.R));
    data.true_poses.push_back(x);

    Step<GlobeCameraDataset::Control, Eigen::Vector3d> step;
    step.dt = o.dt;
    auto detections = detail::visible_points(o, x, data.true_landmarks, strength);
    if (o.response_jitter > 0.0)
      for (auto& d : detections) d.score *= std::exp(jitter(jitter_rng));
    const auto keep = std::min<std::size_t>(detections.size(), static_cast<std::size_t>(o.max_features_per_frame));
    std::partial_sort(detections.begin(), detections.begin() + static_cast<std::ptrdiff_t>(keep), detections.end(),
                      [](const auto& a, const auto& b) { return a.score > b.score; });
    for (std::size_t i = 0; i < keep; ++i) {
      const auto& d = detections[i];
      step.observations.push_back({d.id, d.in_camera + gaussian(o.stereo.covariance(d.in_camera))});
    }
    data.steps.push_back(std::move(step));
  }
  return data;
}

}  // namespace sextant::sim
