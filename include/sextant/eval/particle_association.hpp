#pragma once
/// \file FastSLAM run with the ids of its measurements withheld: every step's measurements go to
/// FastSlam::update_unassociated, where each particle associates them by maximum likelihood (thesis
/// §7.2), and map() reports each landmark under the true id of the measurement that created it, so
/// the run is scored like one with known ids (the particle-filter counterpart of eval::WithheldIds).
///
/// FastSLAM gives the landmark that the g-th measurement handed to update_unassociated starts the id
/// first_unassociated_id + g, in every particle that starts one for it; that is how a landmark is
/// traced back to its measurement here.

#include <span>
#include <vector>

#include "sextant/core/observation.hpp"
#include "sextant/core/update_result.hpp"

namespace sextant::eval {

template <class Backend>
class ParticleAssociation {
 public:
  using State = typename Backend::State;
  using Control = typename Backend::Control;
  using Space = typename Backend::Space;
  using ObservationType = typename Backend::ObservationType;
  using Measurement = typename Backend::Measurement;

  explicit ParticleAssociation(Backend& backend) : backend_(backend) {}

  void predict(const Control& u, double dt) { backend_.predict(u, dt); }

  /// Hands the measurements over without their ids, which are kept to score the map.
  UpdateResult update(std::span<const ObservationType> observations) {
    std::vector<Measurement> z;
    z.reserve(observations.size());
    for (const auto& o : observations) z.push_back(o.z);
    const UpdateResult result = backend_.update_unassociated(std::span<const Measurement>(z));
    for (const auto& o : observations) truth_.push_back(o.landmark_id);  // after the update: it may throw
    return result;
  }
  UpdateResult update(const std::vector<ObservationType>& observations) { return update(std::span(observations)); }

  auto pose() const { return backend_.pose(); }
  /// The back-end's map, each landmark under the true id of the measurement that created it.
  auto map() const {
    auto map = backend_.map();
    const LandmarkId first = backend_.options().first_unassociated_id;
    for (auto& landmark : map)
      if (landmark.id >= first && landmark.id - first < truth_.size()) landmark.id = truth_[landmark.id - first];
    return map;
  }
  void remove_landmark(LandmarkId id) { backend_.remove_landmark(id); }

 private:
  Backend& backend_;
  std::vector<LandmarkId> truth_;  ///< [g]: true id of the g-th measurement handed over
};

}  // namespace sextant::eval
