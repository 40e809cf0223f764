#pragma once
/// \file Stereo features to map landmarks: a feature may take a landmark only when its 3D point
/// passes the chi-square gate on the back-end's predicted measurement (innovation covariance
/// S = H Sigma H^T + Q at the joint marginal of the robot and the landmark, thesis eq. 15) and its
/// descriptor is near the landmark's; among those pairs the nearest descriptors are taken first,
/// one feature per landmark. A feature inside no landmark's gate becomes a new landmark; one inside
/// a gate whose descriptor did not match is left out (it would duplicate a landmark). A
/// re-observation may state a noise of its own (a Student-t's weight, `student_t_dof`).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
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
#include "sextant/core/student_t.hpp"
#include "sextant/vision/stereo_front_end.hpp"
#include "sextant/vision/stereo_matching.hpp"

namespace sextant::vision {

struct MapAssociationOptions {
  double gate_probability = 0.999;  ///< chi-square gate, 3 dof
  /// Per m^3: how dense a new landmark's point is in the camera frame (1 / the volume where one can
  /// appear). A feature inside a landmark's gate that matches no descriptor is left out rather than
  /// made a new landmark, unless that landmark's predictive density there, N(z; z_hat, S), is below
  /// this one: a landmark known only to decimetres (a far wrong match) then no longer blocks every
  /// new one in view. 0: every gate blocks.
  double new_landmark_density = 0.0;
  /// Degrees of freedom nu of a re-observation's error as a Student-t (a Gaussian N(0, Q / lambda)
  /// with lambda ~ Gamma(nu/2, nu/2): heavy tails, core/student_t.hpp). Its noise is scaled by sqrt((nu + NIS) / (nu + 3)),
  /// 1 / sqrt(E[lambda | innovation]) with the innovation taken as t-distributed with scale S (as in
  /// Roth, Özkan and Gustafsson's t filter, 2013), applied to Q alone. A far re-observation weighs
  /// less, a near one more. Nu = 4: Lange, Little and Taylor (JASA 1989). 0: Gaussian.
  double student_t_dof = 0.0;
  /// Largest descriptor distance of a pair: Hamming bits for AKAZE's 486-bit MLDB (unrelated
  /// patches differ in about half), L2 for KAZE's unit-length float descriptors (set it near 0.3).
  /// On the rendered globe (300 frames, docs/results/globe_stereo.md) 60 with the ratio test at 0.8
  /// gave 99.99% right associations and EKF position MAE 3.5 mm; 90 without the test 99.96%, 5.3 mm.
  /// Unset: the detector's value, vision::default_max_descriptor_distance (vision/features.hpp),
  /// which StereoTracker fills in from its front-end's detector (a value that suits one descriptor is
  /// meaningless for another: 60 bits let every pair of KAZE's float descriptors through). A caller
  /// of the association functions below sets it.
  std::optional<double> max_descriptor_distance;
  /// A feature's nearest landmark descriptor among those in whose gate it lies must be nearer than
  /// ratio x the second nearest (Lowe's test); 1 turns the test off.
  double ratio = 0.8;
  std::size_t max_observations = 120;  ///< per frame: associated features first, then new ones
};

/// The largest descriptor distance of a pair; throws invalid_input_error when it is unset, not
/// finite or not > 0.
inline double descriptor_distance_bound(const MapAssociationOptions& o) {
  if (!o.max_descriptor_distance)
    throw invalid_input_error("map association: max_descriptor_distance is unset (vision::default_max_descriptor_distance "
                              "gives the detector's value)");
  const double bound = *o.max_descriptor_distance;
  if (!(bound > 0.0) || !std::isfinite(bound))
    throw invalid_input_error("map association: max_descriptor_distance " + std::to_string(bound) + " must be finite and > 0");
  return bound;
}

/// Throws invalid_input_error naming the first option out of its range (the descriptor bound as
/// descriptor_distance_bound does); every entry point that takes the options calls it first.
inline void require_valid(const MapAssociationOptions& o) {
  if (!(o.gate_probability > 0.0 && o.gate_probability < 1.0))
    throw invalid_input_error("map association: gate_probability " + std::to_string(o.gate_probability) +
                              " must be in (0, 1)");
  if (!(o.new_landmark_density >= 0.0))
    throw invalid_input_error("map association: new_landmark_density " + std::to_string(o.new_landmark_density) +
                              " per m^3 must be >= 0");
  StudentTNoise{o.student_t_dof}.validate("map association: student_t_dof");
  if (!(o.ratio > 0.0))
    throw invalid_input_error("map association: ratio " + std::to_string(o.ratio) + " must be > 0 (1 or more: no ratio test)");
  (void)descriptor_distance_bound(o);
}

/// Which covariance of the robot and a landmark the gate's innovation covariance S comes from.
enum class GateCovariance {
  /// Their joint marginal: a gather from P (EKF), one multi-column solve with the factor of Omega
  /// for all landmarks in view (SEIF; on the globe's dense Omega ~1.8 s a frame at Mmax 1000).
  joint_marginal,
  /// Information-form back-ends: the robot and the landmark conditioned on the rest of the map,
  /// O(1) per landmark (SeifSlam::conditional_joints), S within 1.06x of the exact one on the globe;
  /// back-ends without it use the joint marginal.
  conditional,
};

/// A map landmark's predicted measurement with the inverse of its innovation covariance S = H P H^T
/// + Q, and S's two parts: a feature whose noise is s times the model's (StereoFeature::noise_scale)
/// is gated with H P H^T + s^2 Q. With the parts left zero, S_inverse serves every feature.
struct PredictedLandmark {
  LandmarkId id;
  Eigen::Vector3d z;
  Eigen::Matrix3d S_inverse;
  Eigen::Matrix3d state_part = Eigen::Matrix3d::Zero();  ///< H P H^T
  Eigen::Matrix3d Q = Eigen::Matrix3d::Zero();           ///< the model's measurement noise there

  /// S^-1 for a feature of noise scale s, solved with the Cholesky factor of S (positive definite:
  /// Q is).
  Eigen::Matrix3d S_inverse_for(double s) const {
    if (s == 1.0 || Q.isZero(0.0)) return S_inverse;
    return Eigen::LLT<Eigen::Matrix3d>(state_part + s * s * Q).solve(Eigen::Matrix3d::Identity());
  }
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
  std::size_t returned = 0;  ///< of the associated: returning landmarks (vision/returning_landmarks.hpp)
  std::size_t gated_unmatched = 0;  ///< features inside a gate whose descriptors matched no landmark
};

/// The predicted measurement and innovation covariance of every landmark whose mean lies in front
/// of the camera and projects inside the image (the only ones a feature can be). The means are the
/// ones the back-end's update linearizes at (SEIF's linearization_means(), else landmark_means():
/// O(n), no covariances); S comes from the covariance `gate` names: per landmark where that is a
/// gather (EKF: O(1) blocks of P each, or SEIF's conditional blocks), in one call for all of them
/// where it is a solve (SEIF's joint marginal: one multi-column solve with the factor of Omega
/// instead of one per landmark). The cross terms between landmarks, which only a joint test would
/// need, are not used. Landmarks the model cannot predict or whose S is not positive definite are
/// left out; an Omega that cannot be factorized throws numerical_error.
template <class Backend, class Sensor>
std::vector<PredictedLandmark> predict_landmarks_in_view(const Backend& backend, const Sensor& sensor, const StereoRig& rig,
                                                         int width, int height,
                                                         GateCovariance gate = GateCovariance::joint_marginal) {
  using Prediction = decltype(sensor.predict(pose_mean_of(backend), Eigen::Vector3d{}));
  const auto robot = pose_mean_of(backend);
  std::vector<LandmarkId> in_view;
  std::vector<Prediction> predictions;
  const auto means = [&] {
    if constexpr (requires { backend.linearization_means(); })
      return backend.linearization_means();
    else
      return backend.landmark_means();
  }();
  for (const auto& [id, mean] : means) {
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
  auto add = [&](std::size_t i, const auto& cov, Eigen::Index a) {
    const auto& p = predictions[i];
    const Eigen::Matrix3d state_part = innovation_cross_block(cov, p.J_z_x, p.J_z_m, a, p.J_z_x, p.J_z_m, a);
    const Eigen::LLT<Eigen::Matrix3d> llt(state_part + p.Q);
    if (llt.info() == Eigen::Success)
      out.push_back({in_view[i], p.z, llt.solve(Eigen::Matrix3d::Identity()), state_part, p.Q});
  };
  if (in_view.empty()) return out;
  const std::span<const LandmarkId> ids(in_view);
  if constexpr (requires { backend.conditional_joints(ids); }) {
    if (gate == GateCovariance::conditional) {
      const auto blocks = backend.conditional_joints(ids);
      const Eigen::Index landmark_row = predictions.front().J_z_x.cols();  // the robot's block comes first
      for (std::size_t i = 0; i < in_view.size(); ++i) add(i, blocks[i], landmark_row);
      return out;
    }
  }
  if constexpr (requires { backend.information_matrix(); }) {
    const auto joint = backend.joint_marginal(ids);
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

/// How far a point inside the gate can lie from the prediction: NIS = r^T S^-1 r <= gate implies
/// |r|^2 <= gate lambda_max(S) = gate / lambda_min(S^-1) (a little more, so that rounding never drops one).
inline double gate_reach(const Eigen::Matrix3d& S_inverse, double gate) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(S_inverse, Eigen::EigenvaluesOnly);
  const double smallest = eigen.eigenvalues()(0);
  return smallest > 0.0 ? 1.000001 * std::sqrt(gate / smallest) : std::numeric_limits<double>::infinity();
}

/// The gate's reach for each noise scale s: |r|^2 <= gate lambda_max(S_s) with lambda_max(S_s) <=
/// lambda_max(H P H^T) + s^2 lambda_max(Q), a bound that costs nothing per feature.
struct ScaledReach {
  double state = 0.0, noise = 0.0;  ///< gate times the two largest eigenvalues
  ScaledReach(const PredictedLandmark& p, double gate) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    eigen.computeDirect(p.state_part, Eigen::EigenvaluesOnly);
    state = gate * eigen.eigenvalues()(2);
    eigen.computeDirect(p.Q, Eigen::EigenvaluesOnly);
    noise = gate * eigen.eigenvalues()(2);
  }
  bool may_hold(const Eigen::Vector3d& r, double s) const { return r.squaredNorm() <= 1.000001 * (state + s * s * noise); }
};

/// The NIS below which a feature inside the gate is more likely this landmark than a new point of
/// the given density: N(z; z_hat, S) > density, i.e. NIS < -2 log density - log det S - 3 log 2 pi,
/// and never beyond the gate. At density 0: the gate.
inline double creation_blocking_nis(const Eigen::Matrix3d& S_inverse, double gate, double density) {
  if (!(density > 0.0)) return gate;
  const double log_det_S = -std::log(S_inverse.determinant());
  return std::min(gate, -2.0 * std::log(density) - log_det_S - 3.0 * std::log(2.0 * std::acos(-1.0)));
}

/// Whether the nearest descriptor is kept as a pair: within max_distance, and clearly the nearest
/// (Lowe's test against the second) unless ratio >= 1 turns the test off.
template <class Payload>
bool keeps_descriptor_match(const NearestTwo<Payload>& n, double max_distance, double ratio) {
  return n.best <= max_distance && (ratio >= 1.0 || n.clearly_nearest(ratio));
}

/// Per feature, its nearest landmark descriptor among the landmarks whose gate it is inside, kept
/// when within max_descriptor_distance and the ratio test against the second nearest; `gated[i]`:
/// feature i is inside some gate. Each landmark tests only the features within its gate's reach
/// along x (the same pairs as testing all, in the same order per feature).
inline std::vector<FeaturePair> gated_descriptor_matches(const StereoFrame& frame, std::span<const PredictedLandmark> predicted,
                                                         const LandmarkAppearance& appearance,
                                                         const MapAssociationOptions& o, std::vector<bool>& gated) {
  const double gate = chi_square_quantile(3, o.gate_probability);
  const double max_distance = descriptor_distance_bound(o);
  gated.assign(frame.features.size(), false);
  std::vector<NearestTwo<FeaturePair>> nearest(frame.features.size());
  std::vector<double> xs;  // a landmark's gate can only hold the features whose x lies within its reach
  xs.reserve(frame.features.size());
  for (const StereoFeature& f : frame.features) xs.push_back(f.point.x());
  const SortedIndex by_x(xs);
  double widest = 1.0;  // the largest noise scale among the features: the reach must hold its gate
  bool scaled_features = false;
  for (const StereoFeature& f : frame.features) {
    widest = std::max(widest, f.noise_scale);
    scaled_features |= f.noise_scale != 1.0;
  }
  for (std::size_t j = 0; j < predicted.size(); ++j) {
    const cv::Mat* descriptor = appearance.find(predicted[j].id);
    const double reach = gate_reach(predicted[j].S_inverse_for(widest), gate), x = predicted[j].z.x();
    const double blocking_nis = creation_blocking_nis(predicted[j].S_inverse, gate, o.new_landmark_density);
    const auto scaled = scaled_features ? std::optional<ScaledReach>(std::in_place, predicted[j], gate) : std::nullopt;
    for (const int feature : by_x.band(x, reach)) {
      const auto i = static_cast<std::size_t>(feature);
      const Eigen::Vector3d r = frame.features[i].point - predicted[j].z;
      const double s = frame.features[i].noise_scale;
      if (s != 1.0 && !scaled->may_hold(r, s)) continue;
      const double nis = r.dot(predicted[j].S_inverse_for(s) * r);
      if (!(nis <= gate)) continue;
      gated[i] = gated[i] || nis <= blocking_nis;
      if (!descriptor) continue;
      const double distance = descriptor_distance(frame.descriptors, static_cast<int>(i), *descriptor, 0);
      nearest[i].offer(distance, {i, j, distance, nis});
    }
  }
  std::vector<FeaturePair> pairs;
  for (const auto& n : nearest)
    if (keeps_descriptor_match(n, max_distance, o.ratio)) pairs.push_back(n.nearest);
  return pairs;
}

/// One landmark per feature and one feature per landmark, the closest descriptors first (ties: the
/// smaller innovation): per feature the pair it took, empty for a feature left without one.
inline std::vector<std::optional<FeaturePair>> one_to_one(std::vector<FeaturePair> pairs, std::size_t features,
                                                          std::size_t landmarks) {
  std::sort(pairs.begin(), pairs.end(), [](const FeaturePair& a, const FeaturePair& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.nis < b.nis;
  });
  std::vector<std::optional<FeaturePair>> taken_by(features);
  std::vector<bool> taken(landmarks, false);
  for (const FeaturePair& p : pairs) {
    if (taken_by[p.feature] || taken[p.landmark]) continue;
    taken_by[p.feature] = p;
    taken[p.landmark] = true;
  }
  return taken_by;
}

/// A re-observation's noise scale: the feature's, times the Student-t's where student_t_dof > 0
/// (`nis`: the pair's, under the feature's own gate).
inline double reobservation_noise_scale(double feature_scale, double nis, const MapAssociationOptions& o) {
  return feature_scale * std::sqrt(StudentTNoise{o.student_t_dof}.noise_factor(nis, 3));
}

}  // namespace detail

/// Associates the frame's features with the predicted landmarks; new landmarks take ids
/// next_id, next_id + 1, ... (next_id is advanced). Bad options throw invalid_input_error
/// (require_valid) before next_id changes.
inline FrameAssociation associate_to_map(const StereoFrame& frame, std::span<const PredictedLandmark> predicted,
                                         const LandmarkAppearance& appearance, LandmarkId& next_id,
                                         const MapAssociationOptions& o) {
  require_valid(o);
  std::vector<bool> gated;
  const auto pair_of = detail::one_to_one(detail::gated_descriptor_matches(frame, predicted, appearance, o, gated),
                                          frame.features.size(), predicted.size());
  FrameAssociation out;
  for (std::size_t i = 0; i < frame.features.size() && out.observations.size() < o.max_observations; ++i) {
    if (!pair_of[i]) continue;
    const double scale = detail::reobservation_noise_scale(frame.features[i].noise_scale, pair_of[i]->nis, o);
    out.observations.push_back({predicted[pair_of[i]->landmark].id, frame.features[i].point, scale});
    out.feature.push_back(i);
    ++out.associated;
  }
  for (std::size_t i = 0; i < frame.features.size(); ++i) {
    if (pair_of[i]) continue;
    if (gated[i]) {
      ++out.gated_unmatched;
      continue;
    }
    if (out.observations.size() >= o.max_observations) continue;
    out.observations.push_back({next_id++, frame.features[i].point, frame.features[i].noise_scale});
    out.feature.push_back(i);
    ++out.created;
  }
  return out;
}

}  // namespace sextant::vision
