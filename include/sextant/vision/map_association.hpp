#pragma once
/// \file Stereo features to map landmarks: a feature may take a landmark only when its 3D point
/// passes the chi-square gate on the back-end's predicted measurement (innovation covariance
/// S = H Sigma H^T + Q at the joint marginal of the robot and the landmark, thesis eq. 15) and its
/// descriptor is near the landmark's; among those pairs the nearest descriptors are taken first,
/// one feature per landmark. A feature inside no landmark's gate becomes a new landmark; one inside
/// a gate whose descriptor did not match is left out (it would duplicate a landmark).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "sextant/core/chi_square.hpp"
#include "sextant/core/error.hpp"
#include "sextant/core/joint_marginal.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/core/pose_mean.hpp"
#include "sextant/vision/stereo_front_end.hpp"

namespace sextant::vision {

struct MapAssociationOptions {
  double gate_probability = 0.999;  ///< chi-square gate, 3 dof
  /// Largest descriptor distance of a pair: Hamming bits for AKAZE's 486-bit MLDB (unrelated
  /// patches differ in about half), L2 for KAZE's unit-length float descriptors (set it near 0.3).
  /// On the rendered globe (300 frames, docs/results/globe_stereo.md) 60 with the ratio test at 0.8
  /// gave 99.99% right associations and EKF position MAE 3.5 mm; 90 without the test 99.96%, 5.3 mm.
  double max_descriptor_distance = 60.0;
  /// A feature's nearest landmark descriptor among those in whose gate it lies must be nearer than
  /// ratio x the second nearest (Lowe's test); 1 turns the test off.
  double ratio = 0.8;
  std::size_t max_observations = 120;  ///< per frame: associated features first, then new ones
};

/// A map landmark's predicted measurement with the inverse of its innovation covariance.
struct PredictedLandmark {
  LandmarkId id;
  Eigen::Vector3d z;
  Eigen::Matrix3d S_inverse;
};

/// The descriptor that stands for each landmark in the back-end (vision/stereo_tracker.hpp picks which).
class LandmarkAppearance {
 public:
  void set(LandmarkId id, const cv::Mat& descriptor) { descriptors_[id] = descriptor.clone(); }
  const cv::Mat* find(LandmarkId id) const {
    const auto it = descriptors_.find(id);
    return it == descriptors_.end() ? nullptr : &it->second;
  }
  /// Forgets the landmarks for which `kept(id)` is false (evicted from the back-end).
  template <class Kept>
  void retain(Kept&& kept) {
    std::erase_if(descriptors_, [&](const auto& entry) { return !kept(entry.first); });
  }
  std::size_t size() const { return descriptors_.size(); }

 private:
  std::unordered_map<LandmarkId, cv::Mat> descriptors_;
};

/// What the features of one frame became.
struct FrameAssociation {
  std::vector<Observation<Eigen::Vector3d>> observations;  ///< associated first, then new; ready for update()
  std::vector<std::size_t> feature;                        ///< per observation: its index in the frame
  std::size_t associated = 0, created = 0;
  std::size_t gated_unmatched = 0;  ///< features inside a gate whose descriptors matched no landmark
};

/// The predicted measurement and innovation covariance of every landmark whose mean lies in front
/// of the camera and projects inside the image (the only ones a feature can be). The means come
/// from the back-end's landmark_means() (O(n), no covariances); S from its joint marginal of the robot
/// and each landmark: per landmark where that is a gather (EKF: O(1) blocks of P each), in one call
/// for all of them where it is a solve (an information-form back-end such as SEIF: one multi-column
/// solve with the factor of Omega instead of one per landmark). The cross terms between landmarks,
/// which only a joint test would need, are not used. Landmarks the model cannot predict or whose S
/// is not positive definite are left out; an Omega that cannot be factorized throws numerical_error.
template <class Backend, class Sensor>
std::vector<PredictedLandmark> predict_landmarks_in_view(const Backend& backend, const Sensor& sensor, const StereoRig& rig,
                                                         int width, int height) {
  using Prediction = decltype(sensor.predict(pose_mean_of(backend), Eigen::Vector3d{}));
  const auto robot = pose_mean_of(backend);
  std::vector<LandmarkId> in_view;
  std::vector<Prediction> predictions;
  for (const auto& [id, mean] : backend.landmark_means()) {
    std::optional<Prediction> p;
    try {
      p = sensor.predict(robot, mean);
    } catch (const numerical_error&) {  // the model cannot predict it here (e.g. the camera's gimbal lock)
      continue;
    }
    const Eigen::Vector3d& q = p->z;
    if (!(q.z() > 0.0) || !q.allFinite()) continue;
    const double u = rig.cx + rig.focal_px * q.x() / q.z(), v = rig.cy + rig.focal_px * q.y() / q.z();
    if (!(u >= 0.0 && u < width && v >= 0.0 && v < height)) continue;
    in_view.push_back(id);
    predictions.push_back(std::move(*p));
  }
  std::vector<PredictedLandmark> out;
  auto add = [&](std::size_t i, const Eigen::MatrixXd& cov, Eigen::Index a) {
    const auto& p = predictions[i];
    const Eigen::Matrix3d S = innovation_cross_block(cov, p.J_z_x, p.J_z_m, a, p.J_z_x, p.J_z_m, a) + p.Q;
    const Eigen::LLT<Eigen::Matrix3d> llt(S);
    if (llt.info() == Eigen::Success) out.push_back({in_view[i], p.z, llt.solve(Eigen::Matrix3d::Identity())});
  };
  if (in_view.empty()) return out;
  if constexpr (requires { backend.information_matrix(); }) {
    const auto joint = backend.joint_marginal(std::span<const LandmarkId>(in_view));
    for (std::size_t i = 0; i < in_view.size(); ++i) add(i, joint.cov, joint.offset(i));
  } else {
    for (std::size_t i = 0; i < in_view.size(); ++i) {
      const auto joint = backend.joint_marginal(std::span<const LandmarkId>(&in_view[i], 1));
      add(i, joint.cov, joint.offset(0));
    }
  }
  return out;
}

namespace detail {

/// A feature paired with a predicted landmark: descriptor distance and normalized innovation.
struct FeaturePair {
  std::size_t feature, landmark;
  double distance, nis;
};

/// Per feature, its nearest landmark descriptor among the landmarks whose gate it is inside, kept
/// when within max_descriptor_distance and the ratio test against the second nearest; `gated[i]`:
/// feature i is inside some gate.
inline std::vector<FeaturePair> gated_descriptor_matches(const StereoFrame& frame, std::span<const PredictedLandmark> predicted,
                                                         const LandmarkAppearance& appearance,
                                                         const MapAssociationOptions& o, std::vector<bool>& gated) {
  const double gate = chi_square_quantile(3, o.gate_probability);
  gated.assign(frame.features.size(), false);
  std::vector<FeaturePair> best(frame.features.size(), FeaturePair{0, 0, std::numeric_limits<double>::infinity(), 0.0});
  std::vector<double> second(frame.features.size(), std::numeric_limits<double>::infinity());
  const int norm = frame.descriptors.type() == CV_8U ? cv::NORM_HAMMING : cv::NORM_L2;
  for (std::size_t j = 0; j < predicted.size(); ++j) {
    const cv::Mat* descriptor = appearance.find(predicted[j].id);
    for (std::size_t i = 0; i < frame.features.size(); ++i) {
      const Eigen::Vector3d r = frame.features[i].point - predicted[j].z;
      const double nis = r.dot(predicted[j].S_inverse * r);
      if (!(nis <= gate)) continue;
      gated[i] = true;
      if (!descriptor) continue;
      const double distance = cv::norm(frame.descriptors.row(static_cast<int>(i)), *descriptor, norm);
      if (distance < best[i].distance) {
        second[i] = best[i].distance;
        best[i] = {i, j, distance, nis};
      } else if (distance < second[i]) {
        second[i] = distance;
      }
    }
  }
  std::vector<FeaturePair> pairs;
  for (std::size_t i = 0; i < frame.features.size(); ++i)
    if (best[i].distance <= o.max_descriptor_distance && (o.ratio >= 1.0 || best[i].distance < o.ratio * second[i]))
      pairs.push_back(best[i]);
  return pairs;
}

/// One landmark per feature and one feature per landmark, the closest descriptors first (ties: the
/// smaller innovation); -1 for a feature left without one.
inline std::vector<int> one_to_one(std::vector<FeaturePair> pairs, std::size_t features, std::size_t landmarks) {
  std::sort(pairs.begin(), pairs.end(), [](const FeaturePair& a, const FeaturePair& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.nis < b.nis;
  });
  std::vector<int> landmark_of(features, -1);
  std::vector<bool> taken(landmarks, false);
  for (const FeaturePair& p : pairs) {
    if (landmark_of[p.feature] >= 0 || taken[p.landmark]) continue;
    landmark_of[p.feature] = static_cast<int>(p.landmark);
    taken[p.landmark] = true;
  }
  return landmark_of;
}

}  // namespace detail

/// Associates the frame's features with the predicted landmarks; new landmarks take ids
/// next_id, next_id + 1, ... (next_id is advanced).
inline FrameAssociation associate_to_map(const StereoFrame& frame, std::span<const PredictedLandmark> predicted,
                                         const LandmarkAppearance& appearance, LandmarkId& next_id,
                                         const MapAssociationOptions& o = {}) {
  std::vector<bool> gated;
  const auto landmark_of = detail::one_to_one(detail::gated_descriptor_matches(frame, predicted, appearance, o, gated),
                                              frame.features.size(), predicted.size());
  FrameAssociation out;
  for (std::size_t i = 0; i < frame.features.size() && out.observations.size() < o.max_observations; ++i) {
    if (landmark_of[i] < 0) continue;
    out.observations.push_back({predicted[static_cast<std::size_t>(landmark_of[i])].id, frame.features[i].point});
    out.feature.push_back(i);
    ++out.associated;
  }
  for (std::size_t i = 0; i < frame.features.size(); ++i) {
    if (landmark_of[i] >= 0) continue;
    if (gated[i]) {
      ++out.gated_unmatched;
      continue;
    }
    if (out.observations.size() >= o.max_observations) continue;
    out.observations.push_back({next_id++, frame.features[i].point});
    out.feature.push_back(i);
    ++out.created;
  }
  return out;
}

}  // namespace sextant::vision
