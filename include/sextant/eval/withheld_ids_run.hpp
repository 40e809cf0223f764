#pragma once
/// \file What a run with the ids of its measurements withheld shows the evaluation: the back-end's
/// pose, its map with each landmark under the true id of the measurement that created it, and the
/// association's score. The association itself is the derived class's (CRTP): Derived::update(span)
/// withholds the ids, has the back-end's landmarks found, and records the outcome in score_.

#include <span>
#include <vector>

#include "sextant/core/update_result.hpp"
#include "sextant/eval/association_score.hpp"

namespace sextant::eval {

template <class Derived, class Backend>
class WithheldIdsRun {
 public:
  using State = typename Backend::State;
  using Control = typename Backend::Control;
  using Space = typename Backend::Space;
  using ObservationType = typename Backend::ObservationType;

  explicit WithheldIdsRun(Backend& backend) : backend_(backend) {}

  void predict(const Control& u, double dt) { backend_.predict(u, dt); }
  UpdateResult update(const std::vector<ObservationType>& observations) {
    return static_cast<Derived&>(*this).update(std::span<const ObservationType>(observations));
  }

  auto pose() const { return backend_.pose(); }
  /// The back-end's map, each landmark under the true id of the measurement that created it.
  auto map() const {
    auto map = backend_.map();
    for (auto& landmark : map) landmark.id = score_.truth_of(landmark.id).value_or(landmark.id);
    return map;
  }
  /// Removes a landmark by the id the back-end knows it by.
  void remove_landmark(LandmarkId id) { backend_.remove_landmark(id); }

  const AssociationScore& score() const { return score_; }

 protected:
  Backend& backend_;
  AssociationScore score_;
};

}  // namespace sextant::eval
