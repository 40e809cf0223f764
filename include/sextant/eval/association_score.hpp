#pragma once
/// \file Scores data association against known correspondences: each landmark the association
/// creates takes the true id of the measurement that created it; a pairing is right when the
/// landmark's true id is the measurement's.

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "sextant/core/data_association.hpp"
#include "sextant/core/error.hpp"

namespace sextant::eval {

/// A step's observations split as a run with the ids withheld needs them: the measurements it hands
/// over, and apart from them the true ids it scores by.
template <class Measurement>
struct WithheldStep {
  std::vector<Measurement> z;
  std::vector<LandmarkId> truth;
};

template <class Measurement>
WithheldStep<Measurement> withhold_ids(std::span<const Observation<Measurement>> observations) {
  WithheldStep<Measurement> step;
  step.z.reserve(observations.size());
  step.truth.reserve(observations.size());
  for (const auto& o : observations) {
    step.z.push_back(o.z);
    step.truth.push_back(o.landmark_id);
  }
  return step;
}

class AssociationScore {
 public:
  /// Records one step: true_ids[i] is the true landmark of the i-th associated measurement.
  template <class Measurement>
  void record(std::span<const LandmarkId> true_ids, const AssociationResult<Measurement>& result) {
    if (true_ids.size() != result.outcome.size())
      throw invalid_input_error("association score: " + std::to_string(true_ids.size()) + " true ids for " +
                                std::to_string(result.outcome.size()) + " measurements");
    std::unordered_set<LandmarkId> created_now;
    for (std::size_t i = 0; i < true_ids.size(); ++i) {
      const LandmarkId truth = true_ids[i];
      const bool mapped = mapped_.contains(truth);
      if (mapped) ++should_pair_;
      switch (result.outcome[i]) {
        case AssociationOutcome::paired: {
          const auto it = truth_of_.find(result.id[i]);
          if (it != truth_of_.end() && it->second == truth)
            ++correct_;
          else
            ++wrong_;
          break;
        }
        case AssociationOutcome::new_landmark:
          truth_of_[result.id[i]] = truth;
          if (mapped) ++duplicates_;
          created_now.insert(truth);
          break;
        case AssociationOutcome::discarded:
          ++discarded_;
          break;
      }
    }
    mapped_.insert(created_now.begin(), created_now.end());
    if (!result.search_complete) ++searches_cut_;
  }

  /// Notes the true id of a landmark another hypothesis created, counting nothing: FastSLAM's
  /// particles start their own landmarks, and the particle scored in a later step may pair a
  /// measurement with one that the particle scored when it was made had not started.
  void note_created(LandmarkId created, LandmarkId truth) { truth_of_.emplace(created, truth); }

  /// The true id of a landmark the association created, none for one it did not.
  std::optional<LandmarkId> truth_of(LandmarkId created) const {
    const auto it = truth_of_.find(created);
    return it == truth_of_.end() ? std::nullopt : std::optional(it->second);
  }

  /// Right pairings over all pairings (1 when nothing was paired).
  double precision() const { return correct_ + wrong_ == 0 ? 1.0 : double(correct_) / double(correct_ + wrong_); }
  /// Right pairings over the measurements of landmarks already in the map (1 when there were none).
  double recall() const { return should_pair_ == 0 ? 1.0 : double(correct_) / double(should_pair_); }
  std::size_t correct() const { return correct_; }
  std::size_t wrong() const { return wrong_; }
  /// New landmarks made for a true landmark already in the map.
  std::size_t duplicates() const { return duplicates_; }
  std::size_t discarded() const { return discarded_; }
  /// Steps whose JCBB search stopped at its node limit with the best hypothesis found so far.
  std::size_t searches_cut() const { return searches_cut_; }

 private:
  std::unordered_map<LandmarkId, LandmarkId> truth_of_;  ///< created landmark -> true id
  std::unordered_set<LandmarkId> mapped_;                 ///< true ids with a landmark in the map
  std::size_t correct_ = 0, wrong_ = 0, duplicates_ = 0, discarded_ = 0, should_pair_ = 0, searches_cut_ = 0;
};

}  // namespace sextant::eval
