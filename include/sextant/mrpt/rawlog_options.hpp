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
  /// Standard deviation of the start pose (the robot starts at the origin of the map frame).
  double prior_std = 1e-6;
  /// Read at most this many steps (0: all).
  std::size_t max_steps = 0;
};

}  // namespace sextant::mrpt_io
