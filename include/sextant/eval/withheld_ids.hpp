#pragma once
/// \file A back-end run with the ids of its measurements withheld: every step's measurements go
/// through DataAssociation (nearest neighbour or JCBB), the back-end sees only the ids the
/// association hands out, and map() reports each landmark under the true id of the measurement
/// that created it, so a run with unknown correspondences is scored like one with known ids.

#include <span>

#include "sextant/core/data_association.hpp"
#include "sextant/eval/withheld_ids_run.hpp"

namespace sextant::eval {

template <class Backend, class Sensor>
class WithheldIds : public WithheldIdsRun<WithheldIds<Backend, Sensor>, Backend> {
  using Run = WithheldIdsRun<WithheldIds, Backend>;

 public:
  using typename Run::ObservationType;
  using Measurement = typename Sensor::Measurement;

  WithheldIds(Backend& backend, Sensor sensor, AssociationOptions options)
      : Run(backend), association_(std::move(sensor), options) {}

  using Run::update;
  /// Associates the measurements (their ids are used only to score the association), then updates.
  UpdateResult update(std::span<const ObservationType> observations) {
    const auto step = withhold_ids(observations);
    const auto result = association_.associate(this->backend_, std::span<const Measurement>(step.z));
    const UpdateResult update = this->backend_.update(result.observations);
    this->score_.record(std::span<const LandmarkId>(step.truth), result);
    return update;
  }

 private:
  DataAssociation<Sensor> association_;
};

}  // namespace sextant::eval
