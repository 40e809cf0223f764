#pragma once
/// \file Bookkeeping from landmark ids to dense slots in a stacked state. Removal moves the
/// last slot into the freed one, so slots stay dense and removal costs O(1) here.

#include <cstddef>
#include <string>
#include <unordered_map>
#include <span>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"

namespace sextant {

class LandmarkPool {
 public:
  /// Where removal of a landmark moves things: the freed slot receives the last slot.
  struct Removal {
    std::size_t freed_slot;
    std::size_t last_slot;
  };

  std::size_t size() const { return ids_.size(); }
  bool contains(LandmarkId id) const { return slots_.contains(id); }
  const std::vector<LandmarkId>& ids() const { return ids_; }
  LandmarkId id_at(std::size_t slot) const { return ids_[slot]; }

  /// Slot of a known landmark; throws unknown_landmark_error otherwise.
  std::size_t slot(LandmarkId id) const {
    auto it = slots_.find(id);
    if (it == slots_.end()) throw unknown_landmark_error("unknown landmark id " + std::to_string(id));
    return it->second;
  }

  /// Appends a new landmark and returns its slot; throws duplicate_landmark_error if present.
  std::size_t add(LandmarkId id) {
    if (contains(id)) throw duplicate_landmark_error("landmark id " + std::to_string(id) + " already exists");
    slots_.emplace(id, ids_.size());
    ids_.push_back(id);
    return ids_.size() - 1;
  }

  /// Removes a landmark: the last slot moves into the freed one (a no-op move if they coincide).
  Removal remove(LandmarkId id) {
    const Removal removal{slot(id), ids_.size() - 1};
    const LandmarkId moved = ids_.back();
    ids_[removal.freed_slot] = moved;
    slots_[moved] = removal.freed_slot;
    ids_.pop_back();
    slots_.erase(id);
    return removal;
  }

 private:
  std::unordered_map<LandmarkId, std::size_t> slots_;
  std::vector<LandmarkId> ids_;
};

/// Observations split into those of landmarks the map holds and those of new landmarks, each in
/// the order given.
template <class Measurement>
struct SplitObservations {
  std::vector<Observation<Measurement>> known;
  std::vector<Observation<Measurement>> fresh;
};

/// `map` is anything with contains(id): a LandmarkPool, or FastSLAM's id -> index map.
template <class Map, class Measurement>
SplitObservations<Measurement> split_known_and_new(const Map& map, std::span<const Observation<Measurement>> observations) {
  SplitObservations<Measurement> out;
  for (const auto& observation : observations)
    (map.contains(observation.landmark_id) ? out.known : out.fresh).push_back(observation);
  return out;
}

}  // namespace sextant
