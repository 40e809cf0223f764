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
#include "sextant/eval/withheld_ids_run.hpp"

namespace sextant::eval {

template <class Backend>
class ParticleAssociation : public WithheldIdsRun<ParticleAssociation<Backend>, Backend> {
  using Run = WithheldIdsRun<ParticleAssociation, Backend>;

 public:
  using typename Run::ObservationType;
  using Measurement = typename Backend::Measurement;

  explicit ParticleAssociation(Backend& backend) : Run(backend) {}

  using Run::update;
  /// Hands the measurements over without their ids, which are kept to score the association and the map.
  UpdateResult update(std::span<const ObservationType> observations) {
    const auto step = withhold_ids(observations);
    std::vector<LandmarkId> chosen;
    const UpdateResult result = this->backend_.update_unassociated(std::span<const Measurement>(step.z), &chosen);
    const LandmarkId first_new = this->backend_.options().first_unassociated_id + handed_over_;  // this step's new ids
    handed_over_ += step.z.size();
    AssociationResult<Measurement> association;
    for (std::size_t i = 0; i < step.z.size(); ++i) {
      this->score_.note_created(first_new + i, step.truth[i]);  // some particle may have started it
      association.outcome.push_back(chosen[i] >= first_new ? AssociationOutcome::new_landmark : AssociationOutcome::paired);
      association.id.push_back(chosen[i]);
    }
    this->score_.record(std::span<const LandmarkId>(step.truth), association);
    return result;
  }

  const auto& options() const { return this->backend_.options(); }
  /// FastSLAM's path posterior (FastSlamOptions::keep_paths): the ids enter no pose.
  auto path_posterior() const { return this->backend_.path_posterior(); }

 private:
  std::size_t handed_over_ = 0;  ///< measurements handed to update_unassociated so far
};

}  // namespace sextant::eval
