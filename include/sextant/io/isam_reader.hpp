#pragma once
/// \file Reader for planar landmark-SLAM data in the iSAM text format: odometry records
/// `EDGE2 i j dx dy dth n1..n6` or `ODOMETRY i j dx dy dth n1..n6` and landmark records
/// `LANDMARK i L x y n1..n3`, the noise as the upper triangle of either a square-root information
/// matrix (iSAM, e.g. cityTrees10000) or a covariance matrix (e.g. GTSAM's Victoria Park).
/// The odometry must form one chain (each record starts where the previous one ended).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/io/parse_number.hpp"
#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/models/se2_odometry.hpp"

namespace sextant::io {

/// How the noise values of a record are to be read.
enum class IsamNoise { square_root_information, covariance };

/// A planar landmark-SLAM data set as a step stream.
struct PlanarDataset {
  std::vector<Observation<Eigen::Vector2d>> initial_observations;  ///< seen from the first pose
  std::vector<Step<OdometryIncrement2D, Eigen::Vector2d>> steps;   ///< one per odometry record
  Eigen::Matrix2d landmark_cov = Eigen::Matrix2d::Identity();      ///< of every landmark record
  std::vector<long long> pose_ids;                                 ///< file id of pose k (k = 0 .. steps)
};

namespace detail {

/// Symmetric matrix from its upper triangle, row by row.
template <int N>
Eigen::Matrix<double, N, N> from_upper_triangle(const std::vector<double>& values) {
  Eigen::Matrix<double, N, N> out;
  std::size_t next = 0;
  for (int r = 0; r < N; ++r)
    for (int c = r; c < N; ++c) out(r, c) = out(c, r) = values[next++];
  return out;
}

/// Covariance from the record's noise values.
template <int N>
Eigen::Matrix<double, N, N> noise_covariance(const std::vector<double>& values, IsamNoise form, const std::string& where) {
  if (form == IsamNoise::covariance) {
    const Eigen::Matrix<double, N, N> cov = from_upper_triangle<N>(values);
    if (Eigen::LLT<Eigen::Matrix<double, N, N>>(cov).info() != Eigen::Success)
      throw parse_error(where + ": covariance is not positive definite");
    return cov;
  }
  Eigen::Matrix<double, N, N> R = from_upper_triangle<N>(values);  // upper-triangular square root
  R.template triangularView<Eigen::StrictlyLower>().setZero();
  const Eigen::Matrix<double, N, N> information = R.transpose() * R;
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(information);
  if (llt.info() != Eigen::Success) throw parse_error(where + ": square-root information is singular");
  return llt.solve(Eigen::Matrix<double, N, N>::Identity());
}

}  // namespace detail

/// Reads the file; throws parse_error naming the file and line for anything it cannot use:
/// an unknown record, a wrong number of fields, a value that is not a finite number, noise that is
/// not positive definite, odometry that does not continue the chain, a landmark seen from a pose
/// that is not the newest, a landmark seen twice from one pose, or landmark noise that differs
/// between records.
inline PlanarDataset read_isam_2d(const std::string& path, IsamNoise form) {
  std::ifstream in(path);
  if (!in) throw parse_error(path + ": cannot open file");
  PlanarDataset data;
  bool have_landmark_noise = false;
  std::unordered_set<LandmarkId> seen_from_current_pose;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string where = path + ":" + std::to_string(number);
    std::istringstream fields(line);
    std::string tag;
    if (!(fields >> tag) || tag[0] == '#') continue;
    std::vector<std::string> words;
    for (std::string word; fields >> word;) words.push_back(word);
    std::vector<double> values;
    for (const auto& word : words) {
      const auto value = parse_finite_number(word);
      if (!value) throw parse_error(where + ": '" + word + "' is not a finite number");
      values.push_back(*value);
    }
    auto identifier = [&](double value, const char* what) {
      const auto id = as_identifier(value);
      if (!id) throw parse_error(where + ": " + what + " must be a non-negative integer below 2^53, got " + std::to_string(value));
      return *id;
    };
    auto require_fields = [&](std::size_t count) {
      if (values.size() != count)
        throw parse_error(where + ": " + tag + " needs " + std::to_string(count) + " values, found " +
                          std::to_string(values.size()));
    };
    if (tag == "EDGE2" || tag == "ODOMETRY") {
      require_fields(11);
      const auto from = static_cast<long long>(identifier(values[0], "pose id")),
                 to = static_cast<long long>(identifier(values[1], "pose id"));
      if (data.pose_ids.empty()) data.pose_ids.push_back(from);
      if (from != data.pose_ids.back())
        throw parse_error(where + ": odometry from pose " + std::to_string(from) + " does not continue the chain (newest pose " +
                          std::to_string(data.pose_ids.back()) + "); loop-closure edges are not supported");
      OdometryIncrement2D u;
      u.delta << values[2], values[3], values[4];
      u.cov = detail::noise_covariance<3>({values.begin() + 5, values.end()}, form, where);
      data.steps.push_back({u, 1.0, {}});
      data.pose_ids.push_back(to);
      seen_from_current_pose.clear();
    } else if (tag == "LANDMARK") {
      require_fields(7);
      const auto pose = static_cast<long long>(identifier(values[0], "pose id"));
      if (data.pose_ids.empty()) data.pose_ids.push_back(pose);
      if (pose != data.pose_ids.back())
        throw parse_error(where + ": landmark seen from pose " + std::to_string(pose) + ", but the newest pose is " +
                          std::to_string(data.pose_ids.back()));
      const Eigen::Matrix2d cov = detail::noise_covariance<2>({values.begin() + 4, values.end()}, form, where);
      if (!have_landmark_noise) {
        data.landmark_cov = cov;
        have_landmark_noise = true;
      } else if (!cov.isApprox(data.landmark_cov, 1e-12)) {
        throw parse_error(where + ": landmark noise differs from the first LANDMARK record (one measurement model, one Q)");
      }
      const LandmarkId id = identifier(values[1], "landmark id");
      if (!seen_from_current_pose.insert(id).second)
        throw parse_error(where + ": landmark " + std::to_string(id) + " seen twice from pose " + std::to_string(pose));
      Observation<Eigen::Vector2d> observation{id, Eigen::Vector2d(values[2], values[3])};
      (data.steps.empty() ? data.initial_observations : data.steps.back().observations).push_back(observation);
    } else {
      throw parse_error(where + ": unknown record '" + tag + "'");
    }
  }
  if (data.pose_ids.empty()) throw parse_error(path + ": no odometry or landmark records");
  return data;
}

/// Poses and landmarks of a noise-free data set (e.g. cityTrees10000_groundtruth.txt): poses by
/// composing the odometry from `first_pose`, each landmark from its first observation.
struct PlanarGroundTruth {
  std::vector<Eigen::Vector3d> poses;
  std::map<LandmarkId, Eigen::Vector2d> landmarks;
};

inline PlanarGroundTruth ground_truth_from_noise_free(const PlanarDataset& data,
                                                      const Eigen::Vector3d& first_pose = Eigen::Vector3d::Zero()) {
  PlanarGroundTruth truth;
  truth.poses.push_back(first_pose);
  const PointInRobotFrame2D sensor;
  auto add_landmarks = [&](const std::vector<Observation<Eigen::Vector2d>>& observations) {
    for (const auto& observation : observations)
      truth.landmarks.try_emplace(observation.landmark_id, sensor.initialize(truth.poses.back(), observation.z).m);
  };
  add_landmarks(data.initial_observations);
  for (const auto& step : data.steps) {
    truth.poses.push_back(Se2Odometry{}.predict(truth.poses.back(), step.control, step.dt).x);
    add_landmarks(step.observations);
  }
  return truth;
}

}  // namespace sextant::io
