#pragma once
/// \file FastSLAM run with the ids of its measurements withheld: every step's measurements go to
/// FastSlam::update_unassociated, where each particle associates them by maximum likelihood (thesis
/// §7.2), and map() reports each landmark under the true id of the measurement that created it, so
/// the run is scored like one with known ids (the particle-filter counterpart of eval::WithheldIds).
/// score() scores each step's association made by the particle most likely at that step, the one
/// whose landmarks map() lists.
///
/// FastSLAM gives the landmark that the g-th measurement handed to update_unassociated starts the id
/// first_unassociated_id + g, in every particle that starts one for it; that is how a landmark is
/// traced back to its measurement here.

#include <span>
#include <vector>

#include "sextant/core/observation.hpp"
#include "sextant/core/update_result.hpp"
#include "sextant/eval/association_score.hpp"

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

  /// Hands the measurements over without their ids, which are kept to score the association and the map.
  UpdateResult update(std::span<const ObservationType> observations) {
    const auto step = withhold_ids(observations);
    std::vector<LandmarkId> chosen;
    const UpdateResult result = backend_.update_unassociated(std::span<const Measurement>(step.z), &chosen);
    const LandmarkId first_new = backend_.options().first_unassociated_id + handed_over_;  // this step's new ids
    handed_over_ += step.z.size();
    AssociationResult<Measurement> association;
    for (std::size_t i = 0; i < step.z.size(); ++i) {
      score_.note_created(first_new + i, step.truth[i]);  // some particle may have started it
      association.outcome.push_back(chosen[i] >= first_new ? AssociationOutcome::new_landmark : AssociationOutcome::paired);
      association.id.push_back(chosen[i]);
    }
    score_.record(std::span<const LandmarkId>(step.truth), association);
    return result;
  }
  UpdateResult update(const std::vector<ObservationType>& observations) { return update(std::span(observations)); }

  auto pose() const { return backend_.pose(); }
  /// The back-end's map, each landmark under the true id of the measurement that created it.
  auto map() const {
    auto map = backend_.map();
    for (auto& landmark : map) landmark.id = score_.truth_of(landmark.id).value_or(landmark.id);
    return map;
  }
  void remove_landmark(LandmarkId id) { backend_.remove_landmark(id); }

  /// The association of the step's most likely particle, step by step.
  const AssociationScore& score() const { return score_; }

 private:
  Backend& backend_;
  std::size_t handed_over_ = 0;  ///< measurements handed to update_unassociated so far
  AssociationScore score_;
};

}  // namespace sextant::eval
