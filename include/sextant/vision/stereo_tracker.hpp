#pragma once
/// \file The full image-to-map step of the thesis's vSLAM framework: a filter through the bounded
/// landmark pool tracks the camera (EKF-SLAM or SEIF-SLAM: any back-end with landmark_means() and
/// joint_marginal(); SEIF gates with its conditional blocks by default), and its predictions gate
/// the association of each new stereo frame's features with the map (vision/map_association.hpp).
/// The observations it hands to its back-end, with their landmark ids, are the front-end's output:
/// other back-ends replay them (docs/results/globe_stereo.md says why one association serves them all).

#include <chrono>
#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <vector>

#include "sextant/core/observation.hpp"
#include "sextant/core/seconds_since.hpp"
#include "sextant/core/update_result.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/landmark_pool_policy.hpp"
#include "sextant/models/euler_camera_12d.hpp"
#include "sextant/vision/map_association.hpp"
#include "sextant/vision/returning_landmarks.hpp"
#include "sextant/vision/stereo_front_end.hpp"

namespace sextant::vision {

/// Which descriptor stands for a landmark: the one it was created with, or its latest association's.
/// `latest` follows slow changes of appearance but lets a landmark creep, frame by frame, onto the
/// keypoint's drifting position or a neighbouring feature: on the rendered globe (300 frames) EKF
/// position MAE 13.3 mm and 99.19% right associations, against 5.3 mm and 99.96% with `first`.
enum class LandmarkDescriptor { first, latest };

struct StereoTrackerOptions {
  FrontEndOptions front_end{};
  LandmarkDescriptor descriptor = LandmarkDescriptor::first;
  MapAssociationOptions association{};
  /// What the gate's S comes from; `conditional` changes only information-form back-ends (SEIF),
  /// whose exact joint marginal of every landmark in view costs a factorization of Omega a frame.
  GateCovariance gate_covariance = GateCovariance::conditional;
  PoolLimits pool{};
  /// Landmarks the camera comes back to, verified by one rigid motion (off by default).
  ReturningLandmarkOptions returning{};
};

/// Seconds per stage of one frame: the front-end's three, then association (with the back-end's
/// predictions of the landmarks in view) and the back-end (motion, pool evictions and measurement update).
struct TrackerTimes {
  double detect = 0.0, match = 0.0, triangulate = 0.0, associate = 0.0, backend = 0.0;
  double total() const { return detect + match + triangulate + associate + backend; }
};

struct TrackedFrame {
  std::vector<Observation<Eigen::Vector3d>> observations;  ///< as handed to the pool, associated first
  std::vector<StereoFeature> observed;                     ///< the feature behind each observation
  std::vector<bool> is_new;                                ///< per observation: it proposed a new landmark
  std::size_t left_keypoints = 0, right_keypoints = 0, stereo_matches = 0, predicted = 0, gated_unmatched = 0;
  std::size_t returned = 0;  ///< of the observations: returning landmarks (StereoTrackerOptions::returning)
  std::size_t below_min_disparity = 0;  ///< stereo matches the front-end dropped (FrontEndOptions::min_disparity)
  std::size_t without_support = 0;      ///< and dropped for want of support (FrontEndOptions::disparity_support)
  std::size_t right_refined = 0;        ///< stereo matches whose right x moved (FrontEndOptions::right_refinement)
  std::size_t slant_refined = 0;        ///< stereo matches whose disparity FrontEndOptions::slanted_correlation measured
  std::size_t slant_unmeasured = 0;     ///< and those it dropped, unmeasured
  UpdateResult update;
  TrackerTimes times;
};

/// Tracks with `Backend` (EkfSlam or SeifSlam over a camera motion model and `Sensor`).
template <class Backend, class Sensor = PointInCamera3D>
class StereoTracker {
 public:
  using Control = typename Backend::Control;

  StereoTracker(Backend backend, Sensor sensor, StereoRig rig, int width, int height, StereoTrackerOptions options = {})
      : sensor_(sensor), backend_(std::move(backend)), policy_(options.pool), front_end_(rig, options.front_end),
        width_(width), height_(height), options_(options) {
    auto& max_distance = options_.association.max_descriptor_distance;
    if (!max_distance) max_distance = default_max_descriptor_distance(options.front_end.detector.detector);
    require_valid(options_.association);  // refused before any frame, not in one
    if (options.returning.after_frames > 0) require_valid(options.returning);
  }

  /// One frame: features of the pair, motion update over dt, association, pool, measurement update
  /// (observe, then incorporate). Bad images (empty, not 8-bit, sizes that differ) throw
  /// invalid_input_error before anything changes; the back-end's own steps keep their strong
  /// guarantee, but a failed measurement update leaves the tracker after this frame's motion update,
  /// as eval::run_through_pool does.
  TrackedFrame track(const cv::Mat& left, const cv::Mat& right, const Control& control, double dt) {
    return incorporate(observe(left, right), control, dt);
  }

  /// The front-end's half of a frame (detect, match, triangulate). It reads nothing incorporate
  /// writes, so the next frame's may run on another thread while this one is incorporated
  /// (vision/stereo_sequence_tracking.hpp). Throws as track does for bad images; changes nothing else.
  StereoFrame observe(const cv::Mat& left, const cv::Mat& right) {
    if (left.cols != width_ || left.rows != height_)
      throw invalid_input_error("stereo tracker: a " + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
                                " image, but the camera's images are " + std::to_string(width_) + "x" +
                                std::to_string(height_));
    return front_end_.process(left, right);
  }

  /// The filter's half of a frame observed by observe: motion update over dt, association with the
  /// map, pool, measurement update.
  TrackedFrame incorporate(const StereoFrame& frame, const Control& control, double dt) {
    using Clock = std::chrono::steady_clock;
    TrackedFrame out;
    out.times.detect = frame.times.detect;
    out.times.match = frame.times.match;
    out.times.triangulate = frame.times.triangulate;
    out.left_keypoints = frame.left_keypoints;
    out.right_keypoints = frame.right_keypoints;
    out.stereo_matches = frame.features.size();
    out.below_min_disparity = frame.below_min_disparity;
    out.without_support = frame.without_support;
    out.right_refined = frame.right_refined;
    out.slant_refined = frame.slant_refined;
    out.slant_unmeasured = frame.slant_unmeasured;
    auto start = Clock::now();
    backend_.predict(control, dt);
    out.times.backend = seconds_since(start);
    start = Clock::now();
    const auto predicted = predict_landmarks_in_view(backend_, sensor_, front_end_.rig(), width_, height_,
                                                     options_.gate_covariance);
    auto association = associate_to_map(frame, std::span<const PredictedLandmark>(predicted), appearance_, next_id_,
                                        options_.association);
    if (options_.returning.after_frames > 0)
      associate_returning(frame, predicted, frames_unseen(predicted), appearance_, options_.association,
                          options_.returning, association, next_id_);
    out.times.associate = seconds_since(start);
    out.predicted = predicted.size();
    out.gated_unmatched = association.gated_unmatched;
    out.returned = association.returned;
    start = Clock::now();
    out.update = update_through_pool(backend_, policy_, std::span<const Observation<Eigen::Vector3d>>(association.observations),
                                     step_++);
    out.times.backend += seconds_since(start);
    remember_appearance(frame, association);
    out.observations = association.observations;
    for (std::size_t k = 0; k < association.observations.size(); ++k) {
      out.observed.push_back(frame.features[association.feature[k]]);
      out.is_new.push_back(k >= association.associated);
    }
    return out;
  }

  /// The options it runs with (the association's descriptor distance filled in when unset).
  const StereoTrackerOptions& options() const { return options_; }
  const Backend& backend() const { return backend_; }
  const LandmarkPoolPolicy& pool() const { return policy_; }
  const StereoFrontEnd& front_end() const { return front_end_; }

 private:
  /// Per prediction, the frames since the pool last saw its landmark (this frame is step_).
  std::vector<std::size_t> frames_unseen(std::span<const PredictedLandmark> predicted) const {
    std::vector<std::size_t> out;
    out.reserve(predicted.size());
    for (const PredictedLandmark& p : predicted) out.push_back(step_ - policy_.last_seen(p.id).value_or(step_));
    return out;
  }

  /// The descriptor of every landmark added in this frame (and with `latest`, of every one seen);
  /// evicted ones forgotten.
  void remember_appearance(const StereoFrame& frame, const FrameAssociation& association) {
    for (std::size_t k = 0; k < association.observations.size(); ++k) {
      const LandmarkId id = association.observations[k].landmark_id;
      const bool is_new = k >= association.associated;
      if (policy_.contains(id) && (is_new || options_.descriptor == LandmarkDescriptor::latest))
        appearance_.set(id, frame.descriptors.row(static_cast<int>(association.feature[k])));
    }
    appearance_.retain([&](LandmarkId id) { return policy_.contains(id); });
  }

  Sensor sensor_;
  Backend backend_;
  LandmarkPoolPolicy policy_;
  StereoFrontEnd front_end_;
  LandmarkAppearance appearance_;
  int width_, height_;
  StereoTrackerOptions options_;
  LandmarkId next_id_ = 0;
  std::size_t step_ = 0;
};

}  // namespace sextant::vision
