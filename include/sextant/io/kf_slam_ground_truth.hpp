#pragma once
/// \file Readers for the ground-truth files that come with MRPT's kf-slam demo data sets
/// (/usr/share/mrpt/datasets, Debian mrpt-common): the landmark map, one landmark per row
/// `x y z ... id` (the id in the last column), and the robot path, one pose per row
/// `x y z yaw pitch roll`. Lines starting with '%' or '#' are comments. Plain text: no MRPT needed.

#include <Eigen/Core>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/io/numeric_rows.hpp"
#include "sextant/io/parse_number.hpp"

namespace sextant::io {

/// Landmark positions by id, the first D coordinates of each row (D = 2 or 3).
template <int D>
std::map<LandmarkId, Eigen::Matrix<double, D, 1>> read_kf_slam_landmarks(const std::string& path) {
  static_assert(D == 2 || D == 3);
  std::map<LandmarkId, Eigen::Matrix<double, D, 1>> out;
  for (const auto& [line, values] : detail::read_numeric_rows(path)) {
    const std::string where = path + ":" + std::to_string(line);
    if (values.size() < 4) throw parse_error(where + ": expected 'x y z ... id', got " + std::to_string(values.size()) + " values");
    const auto id = as_identifier(values.back());
    if (!id) throw parse_error(where + ": landmark id must be a non-negative integer below 2^53");
    if (!out.emplace(*id, Eigen::Matrix<double, D, 1>(values.data())).second)
      throw parse_error(where + ": landmark " + std::to_string(*id) + " appears twice");
  }
  if (out.empty()) throw parse_error(path + ": no landmarks");
  return out;
}

/// Robot path rows (x, y, z, yaw, pitch, roll).
inline std::vector<Eigen::Matrix<double, 6, 1>> read_kf_slam_path(const std::string& path) {
  std::vector<Eigen::Matrix<double, 6, 1>> out;
  for (const auto& [line, values] : detail::read_numeric_rows(path)) {
    if (values.size() != 6)
      throw parse_error(path + ":" + std::to_string(line) + ": expected 6 values (x y z yaw pitch roll), got " +
                        std::to_string(values.size()));
    out.emplace_back(values.data());
  }
  if (out.empty()) throw parse_error(path + ": no poses");
  return out;
}

/// The planar part (x, y, yaw) of each pose of a path.
inline std::vector<Eigen::Vector3d> planar_path(const std::vector<Eigen::Matrix<double, 6, 1>>& path) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(path.size());
  for (const auto& p : path) out.emplace_back(p(0), p(1), p(3));
  return out;
}

}  // namespace sextant::io
