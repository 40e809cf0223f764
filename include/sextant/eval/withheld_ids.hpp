#pragma once
/// \file A back-end run with the ids of its measurements withheld: every step's measurements go
/// through DataAssociation (nearest neighbour or JCBB), the back-end sees only the ids the
/// association hands out, and map() reports each landmark under the true id of the measurement
/// that created it, so a run with unknown correspondences is scored like one with known ids.

#include <span>
#include <vector>

#include "sextant/core/data_association.hpp"
#include "sextant/core/update_result.hpp"
#include "sextant/eval/association_score.hpp"

namespace sextant::eval {

template <class Backend, class Sensor>
class WithheldIds {
 public:
  using State = typename Backend::State;
  using Control = typename Backend::Control;
  using Space = typename Backend::Space;
  using ObservationType = typename Backend::ObservationType;
  using Measurement = typename Sensor::Measurement;

  WithheldIds(Backend& backend, Sensor sensor, AssociationOptions options)
      : backend_(backend), association_(std::move(sensor), options) {}

  void predict(const Control& u, double dt) { backend_.predict(u, dt); }

  /// Associates the measurements (their ids are used only to score the association), then updates.
  UpdateResult update(std::span<const ObservationType> observations) {
    const auto step = withhold_ids(observations);
    const auto result = association_.associate(backend_, std::span<const Measurement>(step.z));
    const UpdateResult update = backend_.update(result.observations);
    score_.record(std::span<const LandmarkId>(step.truth), result);
    return update;
  }
  UpdateResult update(const std::vector<ObservationType>& observations) { return update(std::span(observations)); }

  auto pose() const { return backend_.pose(); }
  /// The back-end's map, each landmark under the true id of the measurement that created it.
  auto map() const {
    auto map = backend_.map();
    for (auto& landmark : map) landmark.id = score_.truth_of(landmark.id).value_or(landmark.id);
    return map;
  }
  /// Removes a landmark by the id the association gave it.
  void remove_landmark(LandmarkId id) { backend_.remove_landmark(id); }

  const AssociationScore& score() const { return score_; }

 private:
  Backend& backend_;
  DataAssociation<Sensor> association_;
  AssociationScore score_;
};

}  // namespace sextant::eval
