#pragma once
/// \file Visual-inertial data in the format of seed 004 (UCSD ECE276A, KITTI-derived): a .npz with
/// `time_stamps` (1, T) [s], `linear_velocity` and `angular_velocity` or `rotational_velocity`
/// (3, T) in the IMU frame, `features` (4, M, T) = (uL, vL, uR, vR) pixels of landmark m in frame t,
/// -1 where unseen, `K` (3, 3), `b` (the baseline [m]) and the extrinsic as `imu_T_cam` or
/// `cam_T_imu` (4, 4). Each frame k > 0 becomes one step: the velocity sampled at frame k - 1, held
/// over dt = t_k - t_(k-1), then the stereo observations of frame k; frame 0's observations come
/// before any motion.

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/core/se3.hpp"
#include "sextant/io/implausible_values.hpp"
#include "sextant/io/npz_reader.hpp"
#include "sextant/io/parse_number.hpp"
#include "sextant/models/stereo_imu_se3.hpp"

namespace sextant::io {

struct VisualInertialNpzOptions {
  /// How to read the translation of a `cam_T_imu` key. The files of seed 004's course that use that
  /// key (0027_clean/noisy.npz) store the rotation IMU -> camera axes but the camera's position
  /// in the IMU frame as translation (docs/results/vislam.md: reprojection against both
  /// readings, and KITTI's mounting); true reads it that way, false as a proper cam_T_imu.
  bool cam_T_imu_translation_is_camera_position = true;
  /// The velocities of this format are in KITTI's OXTS axes: x forward, y left, z up (0027's
  /// extrinsic is in those axes and reprojects best as read). 03.npz's `imu_T_cam` instead places
  /// the camera in x-forward, y-right, z-down axes (the camera's x, right, along the IMU's +y):
  /// integrated against it, the yaw rate turns the wrong way for the images (docs/results/vislam.md:
  /// median reprojection 19.4 px as stored, 5.7 px re-based, over five frames). True re-bases such an
  /// extrinsic onto the velocities' axes, imu_T_cam <- diag(1, -1, -1, 1) imu_T_cam; an extrinsic
  /// already in y-left axes is left alone. False: every extrinsic as stored.
  bool rebase_forward_right_down_extrinsic = true;
  /// [s] the longest time between two frames (KITTI's: 0.1 s). A longer one is an error naming the
  /// frame: the IMU's velocities integrated over it would move the camera by whatever they say.
  double max_frame_gap = 60.0;
  /// Beyond these a velocity is used but listed as implausible (VisualInertialDataset::implausible):
  /// the speed in m/s per axis (KITTI's largest 17; a car on a motorway 40), the turn rate in rad/s
  /// per axis (largest 0.66).
  double plausible_speed = 100.0, plausible_rate = 6.283185307179586;
};

struct VisualInertialDataset {
  std::string path;
  std::vector<double> time_stamps;                             ///< T frame times [s]
  std::vector<Observation<Eigen::Vector4d>> first_observations;  ///< frame 0, before any motion
  std::vector<Step<se3::Vector6d, Eigen::Vector4d>> steps;     ///< T - 1: step k ends at frame k + 1
  StereoCalibration calibration;
  Eigen::Matrix4d cam_T_imu = Eigen::Matrix4d::Identity();  ///< proper: maps IMU-frame points to the camera
  std::string extrinsic_key;                               ///< "imu_T_cam" or "cam_T_imu"
  std::size_t landmark_count = 0;                          ///< M: ids are 0 .. M - 1
  std::size_t observation_count = 0;
  std::size_t incomplete_observations = 0;  ///< some but not all four pixels -1: dropped, counted
  ImplausibleValues implausible;  ///< velocities beyond VisualInertialNpzOptions' plausible limits
};

namespace detail {

inline const NpyArray& require_shape(const NpyArray& a, const std::vector<std::size_t>& shape, const std::string& what) {
  if (a.shape != shape) {
    std::string have = "(", want = "(";
    for (const auto d : a.shape) have += std::to_string(d) + ",";
    for (const auto d : shape) want += std::to_string(d) + ",";
    throw parse_error(what + ": shape " + have + ") where " + want + ") was expected");
  }
  for (const double v : a.values) {
    if (!std::isfinite(v)) throw parse_error(what + ": holds a NaN or infinite value");
    if (std::abs(v) > kMaxDataMagnitude) {
      char text[32];
      std::snprintf(text, sizeof text, "%g", v);
      throw parse_error(what + ": holds " + text + ", beyond +-1e12, the largest magnitude sextant reads");
    }
  }
  return a;
}

inline Eigen::Matrix4d read_rigid_transform(const NpzFile& file, const std::string& key) {
  const std::string what = file.path() + ": key '" + key + "'";
  const auto a = file.array(key);
  require_shape(a, {4, 4}, what);
  Eigen::Matrix4d T;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) T(r, c) = a.values[4 * r + c];
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if (!(R.transpose() * R).isIdentity(1e-3) || R.determinant() < 0.0 ||
      !T.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)))
    throw parse_error(what + ": not a rigid transform (rotation not orthonormal or last row not 0 0 0 1)");
  return se3::make(Eigen::Quaterniond(R).normalized().toRotationMatrix(), T.topRightCorner<3, 1>());
}

/// imu_T_cam in x-forward, y-left, z-up IMU axes: re-based by diag(1, -1, -1) (a rotation by pi
/// about x) when the camera's x axis (right) points along the IMU's +y, i.e. y-right, z-down axes.
inline Eigen::Matrix4d in_y_left_axes(const Eigen::Matrix4d& imu_T_cam) {
  if (!(imu_T_cam(1, 0) > 0.5)) return imu_T_cam;
  return Eigen::Vector4d(1.0, -1.0, -1.0, 1.0).asDiagonal() * imu_T_cam;
}

/// The extrinsic as a proper cam_T_imu, from whichever key the file has.
inline Eigen::Matrix4d read_extrinsic(const NpzFile& file, const VisualInertialNpzOptions& options, std::string& key) {
  const bool forward = file.contains("imu_T_cam"), backward = file.contains("cam_T_imu");
  if (forward && backward) throw parse_error(file.path() + ": has both 'imu_T_cam' and 'cam_T_imu'; keep one");
  if (!forward && !backward) throw parse_error(file.path() + ": key 'imu_T_cam' (or 'cam_T_imu') is missing");
  key = forward ? "imu_T_cam" : "cam_T_imu";
  const Eigen::Matrix4d T = read_rigid_transform(file, key);
  if (forward) return se3::inverse(options.rebase_forward_right_down_extrinsic ? in_y_left_axes(T) : T);
  if (!options.cam_T_imu_translation_is_camera_position) return T;
  const Eigen::Matrix3d R = se3::rotation(T);
  return se3::make(R, -R * se3::translation(T));  // translation = the camera's position in the IMU frame
}

inline double read_scalar(const NpzFile& file, const std::string& key) {
  const auto a = file.array(key);
  const std::string what = file.path() + ": key '" + key + "'";
  if (a.values.size() != 1) throw parse_error(what + ": expected one value, found " + std::to_string(a.values.size()));
  return require_shape(a, a.shape, what).values[0];
}

/// time_stamps: shape (1, T) or (T,), strictly increasing.
inline std::vector<double> read_time_stamps(const NpzFile& file, double max_frame_gap) {
  const std::string what = file.path() + ": key 'time_stamps'";
  const auto stamps = file.array("time_stamps");
  if (stamps.values.empty() || stamps.shape.empty() || (stamps.shape.size() == 2 && stamps.shape[0] != 1) || stamps.shape.size() > 2)
    throw parse_error(what + ": expected shape (1, T) or (T,)");
  require_shape(stamps, stamps.shape, what);
  for (std::size_t k = 1; k < stamps.values.size(); ++k) {
    const double dt = stamps.values[k] - stamps.values[k - 1];
    if (!(dt > 0.0))
      throw parse_error(what + ": frame " + std::to_string(k) + " is not later than frame " + std::to_string(k - 1) +
                        " (dt <= 0)");
    if (dt > max_frame_gap)
      throw parse_error(what + ": frame " + std::to_string(k) + " is " + std::to_string(dt) + " s after frame " +
                        std::to_string(k - 1) + ", more than " + std::to_string(max_frame_gap) +
                        " s (VisualInertialNpzOptions::max_frame_gap)");
  }
  return stamps.values;
}

/// K and b: the stereo rig's calibration.
inline StereoCalibration read_calibration(const NpzFile& file) {
  const std::string what = file.path() + ": key ";
  const auto K = file.array("K");
  require_shape(K, {3, 3}, what + "'K'");
  const StereoCalibration calibration{.fx = K.values[0], .fy = K.values[4], .cx = K.values[2], .cy = K.values[5],
                                      .baseline = read_scalar(file, "b")};
  if (!(calibration.fx > 0.0 && calibration.fy > 0.0)) throw parse_error(what + "'K': focal lengths must be positive");
  if (!(calibration.baseline > 0.0)) throw parse_error(what + "'b': the baseline must be positive");
  return calibration;
}

/// features (4, M, T): each landmark m's pixels in frame k, -1 where unseen, into one list per
/// frame; a partly unseen observation is counted and left out.
inline std::vector<std::vector<Observation<Eigen::Vector4d>>> read_frames(const NpzFile& file, std::size_t T,
                                                                           VisualInertialDataset& data) {
  const auto features = file.array("features");
  if (features.shape.size() != 3 || features.shape[0] != 4 || features.shape[2] != T)
    throw parse_error(file.path() + ": key 'features': expected shape (4, M, " + std::to_string(T) + ")");
  require_shape(features, features.shape, file.path() + ": key 'features'");
  const std::size_t M = features.shape[1];
  data.landmark_count = M;
  std::vector<std::vector<Observation<Eigen::Vector4d>>> frames(T);
  for (std::size_t m = 0; m < M; ++m)
    for (std::size_t k = 0; k < T; ++k) {
      Eigen::Vector4d z;
      int unseen = 0;
      for (std::size_t c = 0; c < 4; ++c) {
        z(static_cast<Eigen::Index>(c)) = features.values[(c * M + m) * T + k];
        unseen += z(static_cast<Eigen::Index>(c)) == -1.0;
      }
      if (unseen == 4) continue;
      if (unseen > 0) {
        ++data.incomplete_observations;
        continue;
      }
      frames[k].push_back({static_cast<LandmarkId>(m), z});
      ++data.observation_count;
    }
  return frames;
}

}  // namespace detail

inline VisualInertialDataset read_visual_inertial_npz(const std::string& path, const VisualInertialNpzOptions& options = {}) {
  const NpzFile file(path);
  const auto what = [&](const std::string& key) { return path + ": key '" + key + "'"; };
  VisualInertialDataset data;
  data.path = path;
  data.time_stamps = detail::read_time_stamps(file, options.max_frame_gap);
  const std::size_t T = data.time_stamps.size();

  const std::string angular_key = file.contains("angular_velocity") ? "angular_velocity" : "rotational_velocity";
  if (!file.contains(angular_key)) throw parse_error(what("angular_velocity") + " (or 'rotational_velocity') is missing");
  const auto v = file.array("linear_velocity"), w = file.array(angular_key);
  detail::require_shape(v, {3, T}, what("linear_velocity"));
  detail::require_shape(w, {3, T}, what(angular_key));
  data.calibration = detail::read_calibration(file);
  data.cam_T_imu = detail::read_extrinsic(file, options, data.extrinsic_key);

  auto frames = detail::read_frames(file, T, data);
  data.first_observations = std::move(frames[0]);
  data.steps.reserve(T - 1);
  for (std::size_t k = 1; k < T; ++k) {
    se3::Vector6d u;
    u << v.values[k - 1], v.values[T + k - 1], v.values[2 * T + k - 1], w.values[k - 1], w.values[T + k - 1],
        w.values[2 * T + k - 1];
    data.steps.push_back({u, data.time_stamps[k] - data.time_stamps[k - 1], std::move(frames[k])});
    const std::string where = path + ": frame " + std::to_string(k - 1);
    for (int i = 0; i < 3; ++i) {
      data.implausible.check(u(i), options.plausible_speed, where, "linear velocity", "m/s");
      data.implausible.check(u(3 + i), options.plausible_rate, where, "angular velocity", "rad/s");
    }
  }
  return data;
}

}  // namespace sextant::io
