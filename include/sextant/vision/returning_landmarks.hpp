#pragma once
/// \file Landmarks the camera comes back to (a loop), matched by appearance within a window wider
/// than their gates and verified together by one rigid motion instead of one gate each. An
/// information filter's O(1) gate (the robot and a landmark given the rest of the map,
/// SeifSlam::conditional_joints) leaves out the drift accumulated since the landmark was last seen,
/// so it refuses the very re-observations that would close the loop, and the exact gate costs a
/// factorization of Omega and a solve a frame (3.8 s at Mmax 1000 on the globe,
/// docs/results/real_time.md). Over the part of the map one frame sees, that drift is, to first
/// order, one rigid motion of the camera against the old landmarks: a returning landmark is taken
/// when its descriptor matches a feature (nearest within a window of a set share of its depth,
/// Lowe's ratio test there, one feature each) and that feature lies inside the landmark's own gate
/// once the motion most such pairs agree on is applied (RANSAC over three-point fits, Umeyama's
/// closed form without scale, refitted on its inliers). The landmark's observation is then the
/// feature as measured: the back-end's update sees the whole innovation, drift included, and closes
/// the loop.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/chi_square.hpp"
#include "sextant/eval/alignment.hpp"
#include "sextant/vision/map_association.hpp"
#include "sextant/vision/stereo_matching.hpp"

namespace sextant::vision {

struct ReturningLandmarkOptions {
  /// A landmark in view not associated by its gate and not seen for at least this many frames is
  /// matched as returning; 0 turns the step off.
  std::size_t after_frames = 0;
  /// How far from its prediction a returning landmark's feature may lie, as a share of the
  /// prediction's distance from the camera (0.05: about 3 degrees of drift): its descriptor is matched,
  /// and ratio-tested, only against the features that near.
  double window = 0.05;
  /// The fewest pairs one rigid motion must explain before any is taken (three fix a motion; the
  /// rest are what verifies it).
  std::size_t min_inliers = 10;
  int ransac_iterations = 200;
};

/// Throws invalid_input_error naming the first bad setting: a window that is not positive and
/// finite, fewer than three pairs to fix a motion, no RANSAC iteration.
inline void require_valid(const ReturningLandmarkOptions& r) {
  if (!(r.window > 0.0) || !std::isfinite(r.window))
    throw invalid_input_error("returning landmarks: window " + std::to_string(r.window) + " must be > 0 and finite");
  if (r.min_inliers < 3) throw invalid_input_error("returning landmarks: min_inliers must be >= 3 (a rigid motion)");
  if (r.ransac_iterations < 1) throw invalid_input_error("returning landmarks: ransac_iterations must be >= 1");
}

namespace detail {

/// A returning landmark (index into the predictions) and the feature whose descriptor it matched.
struct ReturningPair {
  std::size_t landmark, feature;
  int distance;
};

/// Per returning landmark the nearest free feature by descriptor within its window, kept within
/// max_descriptor_distance and the ratio test against the second nearest there; one feature per
/// landmark, nearest first.
inline std::vector<ReturningPair> returning_descriptor_pairs(const StereoFrame& frame,
                                                             std::span<const PredictedLandmark> predicted,
                                                             std::span<const std::size_t> returning,
                                                             std::span<const std::size_t> free_features,
                                                             const LandmarkAppearance& appearance,
                                                             const MapAssociationOptions& o, double window) {
  const double max_distance = descriptor_distance_bound(o);
  std::vector<ReturningPair> pairs;
  for (const std::size_t j : returning) {
    const cv::Mat* descriptor = appearance.find(predicted[j].id);
    if (!descriptor) continue;
    NearestTwo<std::size_t> nearest;
    const double reach = window * predicted[j].z.norm();
    for (const std::size_t i : free_features)
      if ((frame.features[i].point - predicted[j].z).squaredNorm() <= reach * reach)
        nearest.offer(descriptor_distance(frame.descriptors, static_cast<int>(i), *descriptor, 0), i);
    if (keeps_descriptor_match(nearest, max_distance, o.ratio))
      pairs.push_back({j, nearest.nearest, static_cast<int>(nearest.best)});
  }
  std::stable_sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.distance < b.distance; });
  std::vector<char> used(frame.features.size(), 0);
  std::erase_if(pairs, [&](const ReturningPair& p) { return std::exchange(used[p.feature], char{1}) != 0; });
  return pairs;
}

/// NIS of pair p under its landmark's gate once the motion T moves the prediction.
inline double moved_nis(const StereoFrame& frame, std::span<const PredictedLandmark> predicted, const ReturningPair& p,
                        const eval::RigidTransform<3>& T) {
  const StereoFeature& f = frame.features[p.feature];
  const Eigen::Vector3d r = f.point - T(predicted[p.landmark].z);
  return r.dot(predicted[p.landmark].S_inverse_for(f.noise_scale) * r);
}

/// The motion that fits its pairs (predicted points onto the features' points).
inline eval::RigidTransform<3> fit_motion(const StereoFrame& frame, std::span<const PredictedLandmark> predicted,
                                          std::span<const ReturningPair> pairs) {
  std::vector<Eigen::Vector3d> from, to;
  for (const ReturningPair& p : pairs) {
    from.push_back(predicted[p.landmark].z);
    to.push_back(frame.features[p.feature].point);
  }
  return eval::align_rigidly<3>(from, to);
}

inline std::vector<ReturningPair> inliers_of(const StereoFrame& frame, std::span<const PredictedLandmark> predicted,
                                             std::span<const ReturningPair> pairs, const eval::RigidTransform<3>& T,
                                             double gate) {
  std::vector<ReturningPair> out;
  for (const ReturningPair& p : pairs)
    if (moved_nis(frame, predicted, p, T) <= gate) out.push_back(p);
  return out;
}

/// The largest set of pairs one rigid motion puts inside their gates (RANSAC, a fixed seed: the same
/// frame gives the same answer), refitted on its inliers until the set stops growing.
inline std::vector<ReturningPair> consistent_pairs(const StereoFrame& frame, std::span<const PredictedLandmark> predicted,
                                                   std::span<const ReturningPair> pairs, double gate, int iterations) {
  std::vector<ReturningPair> best;
  if (pairs.size() < 3) return best;
  std::mt19937_64 random(0x5e87a47);
  std::uniform_int_distribution<std::size_t> pick(0, pairs.size() - 1);
  for (int k = 0; k < iterations; ++k) {
    const std::size_t a = pick(random), b = pick(random), c = pick(random);
    if (a == b || b == c || a == c) continue;
    const ReturningPair sample[] = {pairs[a], pairs[b], pairs[c]};
    auto inliers = inliers_of(frame, predicted, pairs, fit_motion(frame, predicted, sample), gate);
    if (inliers.size() > best.size()) best = std::move(inliers);
  }
  for (std::size_t before = 0; best.size() >= 3 && best.size() > before;) {
    before = best.size();
    auto refitted = inliers_of(frame, predicted, pairs, fit_motion(frame, predicted, best), gate);
    if (refitted.size() < before) break;
    best = std::move(refitted);
  }
  return best;
}

/// `association` with the verified pairs after its associated observations (a re-observation's
/// Student-t weight from its NIS once moved: the drift is not its error) and the new landmarks whose
/// features they did not take, renumbered from the first new id, within the observation cap.
inline std::size_t merge_returning(const StereoFrame& frame, std::span<const PredictedLandmark> predicted,
                                   std::span<const ReturningPair> verified, const eval::RigidTransform<3>& T,
                                   const MapAssociationOptions& o, FrameAssociation& association, LandmarkId& next_id) {
  FrameAssociation out;
  out.gated_unmatched = association.gated_unmatched;
  auto keep = [&](const Observation<Eigen::Vector3d>& observation, std::size_t feature) {
    out.observations.push_back(observation);
    out.feature.push_back(feature);
  };
  for (std::size_t k = 0; k < association.associated; ++k) keep(association.observations[k], association.feature[k]);
  out.associated = association.associated;
  std::vector<bool> used(frame.features.size(), false);
  for (const ReturningPair& p : verified) {
    if (out.observations.size() >= o.max_observations) break;
    const StereoFeature& f = frame.features[p.feature];
    keep({predicted[p.landmark].id, f.point, reobservation_noise_scale(f.noise_scale, moved_nis(frame, predicted, p, T), o)},
         p.feature);
    used[p.feature] = true;
    ++out.associated;
    ++out.returned;
  }
  LandmarkId id = association.created > 0 ? association.observations[association.associated].landmark_id : next_id;
  for (std::size_t k = association.associated; k < association.observations.size(); ++k) {
    if (used[association.feature[k]] || out.observations.size() >= o.max_observations) continue;
    keep({id++, association.observations[k].z, association.observations[k].noise_scale}, association.feature[k]);
    ++out.created;
  }
  next_id = id;
  association = std::move(out);
  return association.returned;
}

}  // namespace detail

/// Adds to `association` (from associate_to_map on the same frame and predictions) the returning
/// landmarks one rigid motion verifies: `frames_unseen[j]` is how long predicted[j] was out of the
/// map's sight. Their features leave the new landmarks they were proposed as (those keep their order
/// and are renumbered from the first new id, next_id with them); the observation cap holds, new
/// landmarks giving way first. Returns how many were added. Bad options (require_valid) or ages that
/// do not match the predictions throw invalid_input_error before `association` changes.
inline std::size_t associate_returning(const StereoFrame& frame, std::span<const PredictedLandmark> predicted,
                                       std::span<const std::size_t> frames_unseen, const LandmarkAppearance& appearance,
                                       const MapAssociationOptions& o, const ReturningLandmarkOptions& r,
                                       FrameAssociation& association, LandmarkId& next_id) {
  if (r.after_frames == 0) return 0;
  if (frames_unseen.size() != predicted.size())
    throw invalid_input_error("returning landmarks: " + std::to_string(frames_unseen.size()) + " ages for " +
                              std::to_string(predicted.size()) + " predicted landmarks");
  require_valid(o);
  require_valid(r);
  std::vector<bool> feature_taken(frame.features.size(), false);
  std::vector<LandmarkId> taken_ids;
  for (std::size_t k = 0; k < association.associated; ++k) {
    feature_taken[association.feature[k]] = true;
    taken_ids.push_back(association.observations[k].landmark_id);
  }
  std::sort(taken_ids.begin(), taken_ids.end());
  std::vector<std::size_t> returning, free_features;
  for (std::size_t j = 0; j < predicted.size(); ++j)
    if (frames_unseen[j] >= r.after_frames && !std::binary_search(taken_ids.begin(), taken_ids.end(), predicted[j].id))
      returning.push_back(j);
  for (std::size_t i = 0; i < frame.features.size(); ++i)
    if (!feature_taken[i]) free_features.push_back(i);
  if (returning.size() < r.min_inliers || free_features.empty()) return 0;
  const auto pairs = detail::returning_descriptor_pairs(frame, predicted, returning, free_features, appearance, o, r.window);
  if (pairs.size() < r.min_inliers) return 0;
  const double gate = chi_square_quantile(3, o.gate_probability);
  const auto T = [&] {
    const auto inliers = detail::consistent_pairs(frame, predicted, pairs, gate, r.ransac_iterations);
    return inliers.size() >= r.min_inliers ? std::optional(detail::fit_motion(frame, predicted, inliers)) : std::nullopt;
  }();
  if (!T) return 0;
  const auto verified = detail::inliers_of(frame, predicted, pairs, *T, gate);
  if (verified.size() < r.min_inliers) return 0;
  return detail::merge_returning(frame, predicted, verified, *T, o, association, next_id);
}

}  // namespace sextant::vision
