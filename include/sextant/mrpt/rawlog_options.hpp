#pragma once
/// \file How the rawlog reader (rawlog.hpp) fills in what a rawlog does not state; apart from the
/// reader so that a program's settings can hold it without parsing MRPT's headers.

#include <Eigen/Core>
#include <cstddef>
#include <optional>

namespace sextant::mrpt_io {

/// What a rawlog does not state, or what a user wants instead of what it states.
struct RawlogOptions {
  /// Replace the sensor noise the rawlog states (standard deviations; range in m, angles in rad).
  std::optional<double> std_range, std_yaw, std_pitch;
  /// Odometry noise (x, y, heading) per step of an observation-only rawlog (CObservationOdometry
  /// carries none); the defaults are MRPT kf-slam's stds_Q_no_odo (0.1 m, 0.1 m, 4 deg).
  Eigen::Vector3d odometry_std = {0.1, 0.1, 4.0 * 3.14159265358979323846 / 180.0};
  /// A step whose odometry increment is exactly zero (every component) is a robot at rest: its
  /// stated standard deviations are multiplied by this factor (1: as stated). MRPT's simul-landmarks
  /// adds no noise to a zero increment yet states its usual covariance (the four steps at rest that
  /// open its logs and MRPT's kf-slam demos), and encoders that count no tick did not move either;
  /// read as stated, those steps blur the whole map's placement by noise that never happened
  /// (docs/results/steps_at_rest.md). Not 0: information-form back-ends invert it.
  double at_rest_noise_scale = 1e-3;
  /// Standard deviation of the start pose (the robot starts at the origin of the map frame).
  double prior_std = 1e-6;
  /// Read at most this many steps (0: all).
  std::size_t max_steps = 0;
};

}  // namespace sextant::mrpt_io
