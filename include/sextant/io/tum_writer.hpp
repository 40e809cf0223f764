#pragma once
/// \file Trajectories in the TUM format: "timestamp tx ty tz qx qy qz qw" per line, readable by
/// evo and the TUM benchmark tools.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <fstream>
#include <iomanip>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"

namespace sextant::io {

struct TumPose {
  double timestamp;
  Eigen::Vector3d position;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

/// A 2D position as a TUM pose (z = 0, identity orientation).
inline TumPose tum_pose_from_position(double timestamp, const Eigen::Vector2d& p) {
  return {timestamp, Eigen::Vector3d(p.x(), p.y(), 0.0)};
}

/// A planar pose (x, y, yaw) as a TUM pose.
inline TumPose tum_pose_from_se2(double timestamp, double x, double y, double yaw) {
  return {timestamp, Eigen::Vector3d(x, y, 0.0), Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))};
}

/// Writes the poses to `path`; throws sextant::error if the file cannot be written.
inline void write_tum(const std::string& path, const std::vector<TumPose>& poses) {
  std::ofstream out(path);
  if (!out) throw error("cannot open " + path + " for writing");
  out << std::setprecision(12);
  for (const auto& p : poses) {
    const auto& q = p.orientation;
    out << p.timestamp << ' ' << p.position.x() << ' ' << p.position.y() << ' ' << p.position.z() << ' ' << q.x()
        << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
  }
}

}  // namespace sextant::io
