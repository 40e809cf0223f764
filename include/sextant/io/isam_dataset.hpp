#pragma once
/// \file A planar data set in the iSAM text format (io/isam_reader.hpp) as the LandmarkDataset every
/// back-end and sextant-run consume: SE(2) odometry with each record's own noise, landmarks as
/// points in the robot frame, and the ground truth when a noise-free companion file lies beside it
/// (cityTrees10000.txt and cityTrees10000_groundtruth.txt). Victoria Park has none.

#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include "sextant/io/isam_reader.hpp"
#include "sextant/io/landmark_dataset.hpp"
#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/models/se2_odometry.hpp"

namespace sextant::io {

using IsamDataset = LandmarkDataset<Se2Odometry, PointInRobotFrame2D>;

/// The noise form of a file, read off its first odometry record: EDGE2 (iSAM) carries the square
/// root of the information matrix, ODOMETRY (GTSAM) the covariance.
inline IsamNoise detect_isam_noise(const std::string& path) {
  std::ifstream in = open_input_file(path);
  std::string line, tag;
  for (int number = 1; std::getline(in, line) && number <= 100000; ++number) {
    std::istringstream fields(line);
    if (!(fields >> tag)) continue;
    if (tag == "EDGE2") return IsamNoise::square_root_information;
    if (tag == "ODOMETRY") return IsamNoise::covariance;
  }
  throw parse_error(path + ": no EDGE2 or ODOMETRY record to tell the noise form from");
}

/// <stem>_groundtruth.txt beside the file, if it exists.
inline std::optional<std::string> isam_ground_truth_file(const std::string& path) {
  const std::filesystem::path p(path);
  const auto truth = p.parent_path() / (p.stem().string() + "_groundtruth" + p.extension().string());
  if (std::filesystem::is_regular_file(truth)) return truth.string();
  return std::nullopt;
}

/// Reads an iSAM-format file. The robot starts at the origin with standard deviation `prior_std`;
/// landmarks seen from the first pose, before any odometry, come in a first step without motion
/// (odometry covariance `still_variance` I, so that every back-end can take it). The ground truth,
/// if a companion file is given or found, is read with the same noise form and must describe the
/// same poses and landmarks.
inline IsamDataset read_isam_dataset(const std::string& path, std::optional<IsamNoise> form = std::nullopt,
                                     double prior_std = 1e-3, double still_variance = 1e-10) {
  const IsamNoise noise = form.value_or(detect_isam_noise(path));
  const PlanarDataset data = read_isam_2d(path, noise);
  IsamDataset out;
  out.path = path;
  out.implausible = data.implausible;
  out.sensor.Q = data.landmark_cov;
  out.prior = {Eigen::Vector3d::Zero(), prior_std * prior_std * Eigen::Matrix3d::Identity()};
  const bool still_step = !data.initial_observations.empty();
  if (still_step)
    out.steps.push_back({OdometryIncrement2D{Eigen::Vector3d::Zero(), still_variance * Eigen::Matrix3d::Identity()}, 1.0,
                         data.initial_observations});
  out.steps.insert(out.steps.end(), data.steps.begin(), data.steps.end());
  const auto truth_path = isam_ground_truth_file(path);
  if (!truth_path) return out;
  const PlanarDataset noise_free = read_isam_2d(*truth_path, noise);
  if (noise_free.steps.size() != data.steps.size())
    throw parse_error(*truth_path + ": " + std::to_string(noise_free.steps.size()) + " odometry records, but " + path +
                      " has " + std::to_string(data.steps.size()));
  auto truth = ground_truth_from_noise_free(noise_free);
  if (still_step) out.true_poses.push_back(truth.poses.front());
  out.true_poses.insert(out.true_poses.end(), truth.poses.begin(), truth.poses.end());
  out.true_landmarks = std::move(truth.landmarks);
  return out;
}

}  // namespace sextant::io
