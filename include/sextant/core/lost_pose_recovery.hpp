#pragma once
/// \file The re-acquisition of a lost pose as a gated filter runs it around its steps (issue 35),
/// one machinery for every back-end that gates (EKF-SLAM, SEIF-SLAM): the record of rejections and
/// questions 1-2 (core/pose_reacquisition.hpp), question 3's probation of a moved copy, and the
/// switch to the copy when it wins. The filter provides, to this class as a friend:
///   std::vector<Sighting> rejected_sightings(observations, const UpdateResult&) const;
///   void reacquire_pose(const Offset& d);  // the pose moved by d, d d^T added to its covariance
///   a member `recovery_` of this type (the copy's is switched off).
/// after_update runs follow_up and has the filter take a winning candidate's estimate.

#include <exception>
#include <memory>
#include <span>
#include <type_traits>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/pose_reacquisition.hpp"
#include "sextant/core/update_result.hpp"

namespace sextant {

template <class Filter, class Reacquisition>
class LostPoseRecovery {
 public:
  using Offset = typename Reacquisition::Offset;
  using Drift = typename Reacquisition::Drift;

  /// Off: nothing is recorded, no candidate is ever made.
  LostPoseRecovery() = default;
  /// gate_probability: the filter's gate, which re-acquisition needs (checked by the record).
  LostPoseRecovery(const ReacquisitionOptions& options, double gate_probability)
      : record_(options, gate_probability), probation_length_(options.probation) {}

  bool on() const { return record_.on(); }

  /// The drift dead reckoning gathers over a motion step (pure), and its commit.
  Drift drift_after(const Drift& G, const Drift& R) const { return record_.drift_after(G, R); }
  void set_drift(const Drift& drift) noexcept { record_.set_drift(drift); }

  /// The candidate under probation takes the filter's step too; one that cannot is dropped.
  template <class Step>
  void follow(Step&& step) {
    if (!probation_.active()) return;
    try {
      step(probation_.candidate());
    } catch (const error&) {
      probation_.drop();
    }
  }

  /// After the filter's committed update: a probation under way scores the update's sightings in
  /// both hypotheses and, once over, returns the candidate if it explained them better (the filter
  /// then takes its estimate; result.pose_reacquired is set); otherwise an update that accepted
  /// nothing adds its rejections to the record and may start a probation. Never throws: a candidate
  /// that cannot take an update is dropped, an attempt that fails (memory, the rejected sightings'
  /// marginals) is skipped with its record, so the filter's update keeps its strong guarantee.
  template <class Observation>
  std::unique_ptr<Filter> follow_up(const Filter& filter, std::span<const Observation> observations,
                                    UpdateResult& result) noexcept {
    if (!on()) return nullptr;
    try {
      if (probation_.active()) {
        double candidate_log_likelihood = 0.0;
        try {
          candidate_log_likelihood = probation_.candidate().update(observations).log_likelihood;
        } catch (const error&) {
          probation_.drop();
        }
        if (probation_.active()) {
          if (auto winner = end_probation_if_over(candidate_log_likelihood, result)) return winner;
          if (probation_.active()) return nullptr;
        }
      }
      if (result.corrected > 0) {
        record_.accepted();
        return nullptr;
      }
      if (result.rejected.empty()) return nullptr;
      if (const auto d = record_.add_rejected(filter.rejected_sightings(observations, result), filter.sensor_))
        start_probation(filter, *d);
    } catch (const std::exception&) {  // memory for a candidate, a marginal the filter cannot give
      probation_.drop();
      record_.forget_record();
    }
    return nullptr;
  }

  /// follow_up on `filter`'s own recovery; a winning candidate's estimate replaces the filter's,
  /// whose re-acquisition record stays its own. Never throws (moves only).
  template <class Observation>
  static void after_update(Filter& filter, std::span<const Observation> observations, UpdateResult& result) noexcept {
    static_assert(std::is_nothrow_move_assignable_v<Filter>, "taking the winner's estimate must not throw");
    auto winner = filter.recovery_.follow_up(filter, observations, result);
    if (!winner) return;
    LostPoseRecovery own = std::move(filter.recovery_);
    filter = std::move(*winner);
    filter.recovery_ = std::move(own);
  }

 private:
  /// The candidate: the filter moved by d, following its steps without re-acquiring itself.
  void start_probation(const Filter& filter, const Offset& d) {
    auto candidate = std::make_unique<Filter>(filter);
    candidate->recovery_ = LostPoseRecovery{};
    try {
      candidate->reacquire_pose(d);
    } catch (const error&) {
      return;
    }
    probation_.start(std::move(candidate));
  }

  /// Counts the update in both hypotheses; at the end of the probation the record starts over, and
  /// the candidate is returned if it explained the sightings better.
  std::unique_ptr<Filter> end_probation_if_over(double candidate_log_likelihood, UpdateResult& result) {
    if (!probation_.count(result.corrected + result.rejected.size(), result.log_likelihood, candidate_log_likelihood,
                          probation_length_))
      return nullptr;
    const bool won = probation_.candidate_won();
    auto candidate = probation_.release();
    record_.forget_record();
    if (!won) return nullptr;
    record_.accepted();
    result.pose_reacquired = true;
    return candidate;
  }

  Reacquisition record_;  ///< the gate's rejections since the last accepted sighting
  PoseProbation<Filter> probation_;  ///< a copy moved to where the rejections say the pose is
  int probation_length_ = 0;
};

}  // namespace sextant
