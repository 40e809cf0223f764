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
#include <optional>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/io/implausible_values.hpp"
#include "sextant/io/input_file.hpp"
#include "sextant/io/parse_number.hpp"
#include "sextant/io/text_record.hpp"
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
  ImplausibleValues implausible;  ///< odometry steps and landmark distances beyond IsamPlausibility
};

/// Beyond these an iSAM record's value is used but listed as implausible: an odometry step's length
/// in m (cityTrees10000's and Victoria Park's largest: 1.5) and a landmark's distance from its pose
/// (largest 20.7).
struct IsamPlausibility {
  double step = 100.0, landmark_distance = 1000.0;
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

/// A covariance an estimator can use: every variance in [1e-24, 1e24] (standard deviations from
/// 1e-12 to 1e12). Outside it the record is legal arithmetic but not usable: a variance of 1e-300
/// (or a square-root information of 1e150) makes an information of 1e300 that overflows the first
/// product an estimator forms with it, and one of 1e300 (a square-root information of 1e-150) is no
/// measurement at all; either would fail far from this line. Victoria Park's smallest variance is
/// 6e-8, cityTrees10000's largest 1e-4.
template <int N>
void require_usable_covariance(const Eigen::Matrix<double, N, N>& cov, const std::string& where, const char* form) {
  if ((cov.diagonal().array() < 1e-24).any())
    throw parse_error(where + ": a variance below 1e-24 (a standard deviation below 1e-12) from this " + form);
  if (!((cov.diagonal().array() <= 1e24).all()))
    throw parse_error(where + ": a variance above 1e24 (a standard deviation above 1e12) from this " + form);
}

/// Covariance from the record's noise values.
template <int N>
Eigen::Matrix<double, N, N> noise_covariance(const std::vector<double>& values, IsamNoise form, const std::string& where) {
  if (form == IsamNoise::covariance) {
    const Eigen::Matrix<double, N, N> cov = from_upper_triangle<N>(values);
    if (Eigen::LLT<Eigen::Matrix<double, N, N>>(cov).info() != Eigen::Success)
      throw parse_error(where + ": covariance is not positive definite");
    require_usable_covariance<N>(cov, where, "covariance");
    return cov;
  }
  Eigen::Matrix<double, N, N> R = from_upper_triangle<N>(values);  // upper-triangular square root
  R.template triangularView<Eigen::StrictlyLower>().setZero();
  if ((R.diagonal().array() == 0.0).any())  // all zero, or a zero on the diagonal: no information in some direction
    throw parse_error(where + ": square-root information is singular (a zero on its diagonal)");
  const Eigen::Matrix<double, N, N> information = R.transpose() * R;
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(information);
  if (llt.info() != Eigen::Success) throw parse_error(where + ": square-root information is singular");
  const Eigen::Matrix<double, N, N> cov = llt.solve(Eigen::Matrix<double, N, N>::Identity());
  require_usable_covariance<N>(cov, where, "square-root information");
  return cov;
}

using IsamRecord = TextRecord;

/// Builds the data set record by record (read_isam_2d).
class IsamDatasetBuilder {
 public:
  explicit IsamDatasetBuilder(IsamNoise form) : form_(form) {}

  void add(const IsamRecord& record) {
    if (record.tag == "EDGE2" || record.tag == "ODOMETRY") return add_odometry(record);
    if (record.tag == "LANDMARK") return add_landmark(record);
    throw parse_error(record.where + ": unknown record '" + record.tag + "'");
  }
  PlanarDataset& data() { return data_; }

 private:
  void add_odometry(const IsamRecord& record) {
    record.require_fields(11);
    const auto from = static_cast<long long>(record.identifier(0, "pose id")),
               to = static_cast<long long>(record.identifier(1, "pose id"));
    if (data_.pose_ids.empty()) data_.pose_ids.push_back(from);
    if (from != data_.pose_ids.back())
      throw parse_error(record.where + ": odometry from pose " + std::to_string(from) +
                        " does not continue the chain (newest pose " + std::to_string(data_.pose_ids.back()) +
                        "); loop-closure edges are not supported");
    OdometryIncrement2D u;
    u.delta << record.values[2], record.values[3], record.values[4];
    data_.implausible.check(u.delta.head<2>().norm(), IsamPlausibility{}.step, record.where, "odometry step of", "m");
    u.cov = noise_covariance<3>({record.values.begin() + 5, record.values.end()}, form_, record.where);
    data_.steps.push_back({u, 1.0, {}});
    data_.pose_ids.push_back(to);
    seen_from_current_pose_.clear();
  }

  void add_landmark(const IsamRecord& record) {
    record.require_fields(7);
    const auto pose = static_cast<long long>(record.identifier(0, "pose id"));
    if (data_.pose_ids.empty()) data_.pose_ids.push_back(pose);
    if (pose != data_.pose_ids.back())
      throw parse_error(record.where + ": landmark seen from pose " + std::to_string(pose) + ", but the newest pose is " +
                        std::to_string(data_.pose_ids.back()));
    const Eigen::Matrix2d cov = noise_covariance<2>({record.values.begin() + 4, record.values.end()}, form_, record.where);
    if (!have_landmark_noise_) {
      data_.landmark_cov = cov;
      have_landmark_noise_ = true;
    } else if (!cov.isApprox(data_.landmark_cov, 1e-12)) {
      throw parse_error(record.where + ": landmark noise differs from the first LANDMARK record (one measurement model, one Q)");
    }
    const LandmarkId id = record.identifier(1, "landmark id");
    if (!seen_from_current_pose_.insert(id).second)
      throw parse_error(record.where + ": landmark " + std::to_string(id) + " seen twice from pose " + std::to_string(pose));
    Observation<Eigen::Vector2d> observation{id, Eigen::Vector2d(record.values[2], record.values[3])};
    data_.implausible.check(observation.z.norm(), IsamPlausibility{}.landmark_distance, record.where,
                            "landmark at a distance of", "m");
    (data_.steps.empty() ? data_.initial_observations : data_.steps.back().observations).push_back(observation);
  }

  IsamNoise form_;
  PlanarDataset data_;
  bool have_landmark_noise_ = false;
  std::unordered_set<LandmarkId> seen_from_current_pose_;
};

}  // namespace detail

/// Reads the file; throws parse_error naming the file and line for anything it cannot use:
/// an unknown record, a wrong number of fields, a value that is not a finite number, noise that is
/// not positive definite, odometry that does not continue the chain, a landmark seen from a pose
/// that is not the newest, a landmark seen twice from one pose, or landmark noise that differs
/// between records.
inline PlanarDataset read_isam_2d(const std::string& path, IsamNoise form) {
  std::ifstream in = open_input_file(path);
  detail::IsamDatasetBuilder builder(form);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number)
    if (const auto record = detail::parse_text_record(line, path + ":" + std::to_string(number))) builder.add(*record);
  if (builder.data().pose_ids.empty()) throw parse_error(path + ": no odometry or landmark records");
  return std::move(builder.data());
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
