#pragma once
/// \file The rendered globe's answer key for the front-end (sim/globe_render.hpp): a new landmark's
/// true point is the globe's surface behind its first left keypoint; a later association of that
/// landmark is right when its true point faces the camera and projects into the new left
/// keypoint's support (its radius, at least 2 px): the same criterion as a right stereo match
/// (tests/vision/stereo_front_end_test.cpp).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "sextant/models/euler_camera_12d.hpp"
#include "sextant/sim/globe_render.hpp"
#include "sextant/vision/stereo_tracker.hpp"

namespace sextant::eval {

class GlobeAssociationTruth {
 public:
  explicit GlobeAssociationTruth(sim::GlobeCameraOptions options) : options_(options) {}

  /// Scores one tracked frame seen from the true pose x.
  void score(const Vector12d& x, const vision::TrackedFrame& frame) {
    for (std::size_t k = 0; k < frame.observations.size(); ++k) {
      const LandmarkId id = frame.observations[k].landmark_id;
      const vision::StereoFeature& f = frame.observed[k];
      if (frame.is_new[k]) {
        add_new(x, id, f);
        continue;
      }
      ++associated_;
      const auto it = true_points_.find(id);
      if (it != true_points_.end() && seen_at(x, it->second, f)) {
        ++right_;
        add_error(x, it->second, frame.observations[k], f);
      }
    }
  }

  /// The right re-observations' NIS against their landmark's true point seen from the true pose,
  /// under the noise the observation states (the sensor's, times its noise_scale squared): 3 dof,
  /// so a mean of 3 and 95% inside 7.81 if the stated noise is honest.
  double mean_nis() const { return nis_.empty() ? 0.0 : nis_sum_ / static_cast<double>(nis_.size()); }
  double median_nis() const {
    if (nis_.empty()) return 0.0;
    auto v = nis_;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  }
  double share_of_nis_within(double bound) const {
    if (nis_.empty()) return 0.0;
    const auto inside = std::count_if(nis_.begin(), nis_.end(), [&](double n) { return n <= bound; });
    return static_cast<double>(inside) / static_cast<double>(nis_.size());
  }
  /// Root mean square of the left keypoint's offset from the true point's projection [px].
  double pixel_rms() const { return nis_.empty() ? 0.0 : std::sqrt(pixel_sq_sum_ / static_cast<double>(nis_.size())); }

  /// New landmarks from a wrong stereo match (sim::stereo_match_is_right false) or whose left
  /// keypoint shows no globe.
  std::size_t new_from_wrong_matches() const { return new_from_wrong_matches_; }
  std::size_t created() const { return created_; }
  std::size_t associated() const { return associated_; }
  std::size_t right() const { return right_; }
  double precision() const { return associated_ ? static_cast<double>(right_) / static_cast<double>(associated_) : 1.0; }
  /// The true point of every landmark the front-end proposed (where its first keypoint showed the globe).
  const std::map<LandmarkId, Eigen::Vector3d>& true_landmarks() const { return true_points_; }

 private:
  bool seen_at(const Vector12d& x, const Eigen::Vector3d& m, const vision::StereoFeature& f) const {
    const Eigen::Vector3d p = x.head<3>();
    if (m.dot(p - m) <= 0.0) return false;  // on the far hemisphere
    const Eigen::Vector3d q = sim::in_left_camera(x, m);
    if (q.z() <= 0.0) return false;
    return (sim::left_pixel(options_, q) - f.left_px).norm() <= sim::keypoint_support_px(f.size);
  }

  /// Keeps a new landmark's true point and scores its stereo match (new_from_wrong_matches).
  void add_new(const Vector12d& x, LandmarkId id, const vision::StereoFeature& f) {
    ++created_;
    const auto m = sim::surface_point(options_, x, f.left_px.x(), f.left_px.y());
    if (m) true_points_.emplace(id, *m);
    new_from_wrong_matches_ += !(m && sim::stereo_match_is_right(options_, x, f.left_px, f.right_px, f.size));
  }

  /// The observation's error against the true point m seen from x, weighed by its stated noise.
  void add_error(const Vector12d& x, const Eigen::Vector3d& m, const Observation<Eigen::Vector3d>& o,
                 const vision::StereoFeature& f) {
    const Eigen::Vector3d q = sim::in_left_camera(x, m);
    const Eigen::Vector3d e = o.z - q;
    const Eigen::Matrix3d stated = o.noise_scale * o.noise_scale * options_.stereo.covariance(q);
    const double nis = e.dot(stated.ldlt().solve(e));
    nis_sum_ += nis;
    nis_.push_back(nis);
    pixel_sq_sum_ += (sim::left_pixel(options_, q) - f.left_px).squaredNorm();
  }

  sim::GlobeCameraOptions options_;
  double nis_sum_ = 0.0, pixel_sq_sum_ = 0.0;
  std::vector<double> nis_;
  std::map<LandmarkId, Eigen::Vector3d> true_points_;
  std::size_t associated_ = 0, right_ = 0, created_ = 0, new_from_wrong_matches_ = 0;
};

}  // namespace sextant::eval
