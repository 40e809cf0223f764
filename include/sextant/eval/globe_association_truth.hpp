#pragma once
/// \file The rendered globe's answer key for the front-end (sim/globe_render.hpp): a new landmark's
/// true point is the globe's surface behind its first left keypoint; a later association of that
/// landmark is right when its true point faces the camera and projects into the new left
/// keypoint's support (its radius, at least 2 px): the same criterion as a right stereo match
/// (tests/vision/stereo_front_end_test.cpp).

#include <Eigen/Core>
#include <algorithm>
#include <map>

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
        if (const auto m = sim::surface_point(options_, x, f.left_px.x(), f.left_px.y())) true_points_.emplace(id, *m);
        continue;
      }
      ++associated_;
      const auto it = true_points_.find(id);
      if (it != true_points_.end() && seen_at(x, it->second, f)) ++right_;
    }
  }

  std::size_t associated() const { return associated_; }
  std::size_t right() const { return right_; }
  double precision() const { return associated_ ? static_cast<double>(right_) / static_cast<double>(associated_) : 1.0; }
  /// The true point of every landmark the front-end proposed (where its first keypoint showed the globe).
  const std::map<LandmarkId, Eigen::Vector3d>& true_landmarks() const { return true_points_; }

 private:
  bool seen_at(const Vector12d& x, const Eigen::Vector3d& m, const vision::StereoFeature& f) const {
    const Eigen::Vector3d p = x.head<3>();
    if (m.dot(p - m) <= 0.0) return false;  // on the far hemisphere
    const Eigen::Vector3d q = euler_yxz::rotation(x.segment<3>(3)).transpose() * (m - p);
    if (q.z() <= 0.0) return false;
    const double f_px = options_.stereo.focal_px;
    const Eigen::Vector2d pixel(0.5 * options_.image_width + f_px * q.x() / q.z(),
                                0.5 * options_.image_height + f_px * q.y() / q.z());
    return (pixel - f.left_px).norm() <= std::max(0.5 * f.size, 2.0);
  }

  sim::GlobeCameraOptions options_;
  std::map<LandmarkId, Eigen::Vector3d> true_points_;
  std::size_t associated_ = 0, right_ = 0;
};

}  // namespace sextant::eval
