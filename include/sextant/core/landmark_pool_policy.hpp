#pragma once
/// \file The thesis's bounded landmark pool (seed 000, §4.2.2: P.Mmax and P.max_lm_inc_per_step):
/// at most max_landmarks in the state, at most max_new_per_step added per step, and when full the
/// least recently seen landmarks are evicted to make room (or those seen in the fewest steps,
/// PoolEviction). The policy only decides; each back-end
/// removes by its own rule through remove_landmark (EKF: rows and columns deleted; SEIF and
/// GraphSLAM: marginalization; FastSLAM: from every particle).

#include <algorithm>
#include <concepts>
#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/core/update_result.hpp"
#include "sextant/core/validation.hpp"

namespace sextant {

/// Which landmarks make room when the pool is full; never one observed in the step.
enum class PoolEviction {
  least_recently_seen,  ///< the thesis's: the oldest last sighting first (ties: the smaller id)
  /// The landmark seen in the fewest steps first (ties: the least recently seen, then the smaller
  /// id): a point tracked over many frames stays for when the camera comes back (a loop), while
  /// points seen once or twice, most of an image front-end's new ones, make the room.
  fewest_sightings,
  /// As fewest_sightings, passing over a landmark whose removal would add links to the back-end's
  /// information form (SEIF: its neighbours are not linked pair by pair; an exact marginalization
  /// links them) while one that adds none is left; the rest, when needed, least recently seen first
  /// (which keeps the fill in the band of recent links). A back-end without links adds none.
  fewest_sightings_without_fill,
};

struct PoolLimits {
  std::size_t max_landmarks = 1000;   ///< Mmax
  std::size_t max_new_per_step = 50;  ///< max_lm_inc_per_step
  PoolEviction eviction = PoolEviction::least_recently_seen;
};

/// Bookkeeping of one step (the thesis's Figures 22 and 25).
struct PoolStepRecord {
  std::size_t in_pool = 0;  ///< landmarks in the state after the step
  std::size_t added = 0;
  std::size_t evicted = 0;
  std::size_t refused = 0;  ///< observations of new landmarks left out (per-step limit or pool full)
  std::size_t unusable = 0;  ///< observations the back-end could not use (UpdateResult::unusable)
};

/// What one step does: landmarks to remove first, then the observations to hand to update().
template <class Measurement>
struct PoolPlan {
  std::vector<LandmarkId> evict;
  std::vector<Observation<Measurement>> observations;  ///< every known one, and the admitted new ones
  std::size_t added = 0, refused = 0;
};

class LandmarkPoolPolicy {
 public:
  explicit LandmarkPoolPolicy(PoolLimits limits) : limits_(limits) {
    if (limits.max_landmarks == 0) throw invalid_input_error("landmark pool: max_landmarks must be > 0");
  }

  const PoolLimits& limits() const { return limits_; }
  std::size_t size() const { return sightings_.size(); }
  bool contains(LandmarkId id) const { return sightings_.contains(id); }
  /// The step a pool landmark was last seen at; none for a landmark not in the pool.
  std::optional<std::size_t> last_seen(LandmarkId id) const {
    const auto it = sightings_.find(id);
    return it == sightings_.end() ? std::nullopt : std::optional(it->second.last);
  }
  const std::vector<PoolStepRecord>& history() const { return history_; }

  /// Plans one step without changing the policy: observations of landmarks in the pool pass; new
  /// ones are admitted in the order given (a front-end lists its strongest first) up to
  /// max_new_per_step and up to what eviction can free; the landmarks to evict come in the order
  /// PoolLimits::eviction names, never one observed in this step.
  template <class Measurement>
  PoolPlan<Measurement> plan(std::span<const Observation<Measurement>> observations) const {
    return plan(observations, [](LandmarkId) { return true; });
  }
  /// The same, with the back-end's answer to "would removing this landmark add no link?" for
  /// PoolEviction::fewest_sightings_without_fill (the other orders do not ask it).
  template <class Measurement, class AddsNoLinks>
  PoolPlan<Measurement> plan(std::span<const Observation<Measurement>> observations, AddsNoLinks adds_no_links) const {
    require_valid_observations(observations);  // the back-ends' own check: finite, no id twice
    PoolPlan<Measurement> out;
    std::unordered_set<LandmarkId> seen_now;
    std::vector<const Observation<Measurement>*> fresh;
    for (const auto& observation : observations) {
      seen_now.insert(observation.landmark_id);
      if (contains(observation.landmark_id))
        out.observations.push_back(observation);
      else
        fresh.push_back(&observation);
    }
    const std::size_t known = out.observations.size();
    // At most max_landmarks - known new ones fit beside the known, so `over` never exceeds the
    // size() - known landmarks that may be evicted.
    const std::size_t room = limits_.max_landmarks - known;
    const std::size_t admit = std::min({fresh.size(), limits_.max_new_per_step, room});
    for (std::size_t i = 0; i < admit; ++i) out.observations.push_back(*fresh[i]);
    out.added = admit;
    out.refused = fresh.size() - admit;
    const std::size_t over = size() + admit > limits_.max_landmarks ? size() + admit - limits_.max_landmarks : 0;
    const bool ask = limits_.eviction == PoolEviction::fewest_sightings_without_fill;
    out.evict = evictions(over, seen_now, [&](LandmarkId id) { return !ask || adds_no_links(id); });
    return out;
  }

  /// Records that the back-end has removed a landmark.
  void evicted(LandmarkId id) { forget(id); }

  /// Records a plan once the back-end has updated with its observations (after evicting);
  /// `step` orders the last sightings. `unusable`: the ids the back-end could not use
  /// (UpdateResult::unusable): not sightings, and a new one among them was not added.
  template <class Measurement>
  void commit(const PoolPlan<Measurement>& plan, std::size_t step, std::span<const LandmarkId> unusable = {}) {
    for (LandmarkId id : plan.evict) forget(id);
    const std::unordered_set<LandmarkId> skipped(unusable.begin(), unusable.end());
    std::size_t not_added = 0;
    for (const auto& observation : plan.observations) {
      if (!skipped.contains(observation.landmark_id))
        see(observation.landmark_id, step);
      else if (!contains(observation.landmark_id))
        ++not_added;
    }
    history_.push_back({size(), plan.added - not_added, plan.evict.size(), plan.refused, skipped.size()});
  }

 private:
  struct Sightings {
    std::size_t last = 0;   ///< the step it was last seen at
    std::size_t steps = 0;  ///< how many steps it was seen at
  };
  /// (steps seen, or 0 for the thesis's order; last seen; id): the first to make room first.
  using EvictionKey = std::tuple<std::size_t, std::size_t, LandmarkId>;
  EvictionKey eviction_key(LandmarkId id, const Sightings& s) const {
    return {limits_.eviction == PoolEviction::least_recently_seen ? 0 : s.steps, s.last, id};
  }
  /// `count` landmarks not seen now: in the eviction order those whose removal adds no link (every
  /// one, for the orders that do not ask), then the others least recently seen first. The answers
  /// are all asked before any removal: removing a vertex whose neighbours form a clique keeps every
  /// other such vertex one, and the removals with fill come after all those without.
  template <class AddsNoLinks>
  std::vector<LandmarkId> evictions(std::size_t count, const std::unordered_set<LandmarkId>& seen_now,
                                    AddsNoLinks adds_no_links) const {
    std::vector<LandmarkId> out;
    std::vector<std::pair<std::size_t, LandmarkId>> with_fill;  // (last seen, id)
    for (auto it = eviction_order_.begin(); out.size() < count && it != eviction_order_.end(); ++it) {
      const LandmarkId id = std::get<2>(*it);
      if (seen_now.contains(id)) continue;
      if (adds_no_links(id))
        out.push_back(id);
      else
        with_fill.emplace_back(std::get<1>(*it), id);
    }
    std::sort(with_fill.begin(), with_fill.end());
    for (std::size_t k = 0; out.size() < count && k < with_fill.size(); ++k) out.push_back(with_fill[k].second);
    return out;
  }
  void forget(LandmarkId id) {
    const auto it = sightings_.find(id);
    if (it == sightings_.end()) return;
    eviction_order_.erase(eviction_key(id, it->second));
    sightings_.erase(it);
  }
  void see(LandmarkId id, std::size_t step) {
    const auto it = sightings_.find(id);
    const Sightings seen{step, it == sightings_.end() ? 1 : it->second.steps + (step != it->second.last)};
    forget(id);
    sightings_.emplace(id, seen);
    eviction_order_.insert(eviction_key(id, seen));
  }

  PoolLimits limits_;
  std::unordered_map<LandmarkId, Sightings> sightings_;
  std::set<EvictionKey> eviction_order_;
  std::vector<PoolStepRecord> history_;
};

/// One step of a back-end through the pool: evict, then update with the admitted observations,
/// then record (new landmarks the back-end could not use are not recorded as added). Policy and back-end stay in step if the back-end throws: each removal is recorded
/// as it succeeds, the sightings only after the update succeeds.
template <class Backend, class Measurement>
UpdateResult update_through_pool(Backend& backend, LandmarkPoolPolicy& policy,
                                 std::span<const Observation<Measurement>> observations, std::size_t step) {
  auto plan = [&] {
    if constexpr (requires(const Backend& b, LandmarkId id) { { b.removal_adds_no_links(id) } -> std::convertible_to<bool>; })
      return policy.plan(observations, [&](LandmarkId id) { return std::as_const(backend).removal_adds_no_links(id); });
    else
      return policy.plan(observations);
  }();
  for (LandmarkId id : plan.evict) {
    backend.remove_landmark(id);
    policy.evicted(id);
  }
  UpdateResult result = backend.update(std::span<const Observation<Measurement>>(plan.observations));
  policy.commit(plan, step, std::span<const LandmarkId>(result.unusable));
  return result;
}

}  // namespace sextant
